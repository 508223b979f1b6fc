#!/usr/bin/env bash
# `armfault report` of a replay of an import (item 4): the import's campaign.json is a
# stand-in whose cases are not the runs, so the records are checked against the import's
# manifest.jsonl (replay.json names it); the sections that re-simulate a run say why they are
# empty; a robot preset is accepted as --twin (the recording found through replay.json); a
# results.jsonl of other data is still refused (exit 2).
# Usage: import_replay_report_test.sh ARMFAULT SOURCE_DIR
set -u
armfault=$1
src=$2
h=$src/tests/campaigns/data
py=/usr/bin/python3  # Debian's, with numpy (import_standin.py)
[ -x "$py" ] || py=python3
tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_impreport.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 2
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$armfault" export "$h/import_standin.json" -o sim -q > export.out 2>&1 || fail "export: $(tail -3 export.out)"
"$py" "$h/import_standin.py" write sim logs > write.out 2>&1 || fail "import_standin.py: $(tail -3 write.out)"
"$armfault" import logs/rig_0*.csv --map logs/map_files.json -o imp -q > import.out 2>&1 || fail "import: $(tail -3 import.out)"
"$armfault" replay imp -q > replay.out 2>&1
[ -f imp/replayed/summary.json ] || fail "replay wrote no summary: $(tail -3 replay.out)"
"$py" - imp/replayed/replay.json "$tmp/imp" <<'PY' || fail "replay.json: $(cat imp/replayed/replay.json)"
import json, os, sys
j = json.load(open(sys.argv[1]))
assert sorted(j) == ["import", "source", "source_absolute"], j
assert j["source"] == "imp" and j["import"] is True and os.path.samefile(j["source_absolute"], sys.argv[2]), j
PY

# The report: exit 0, both files, the re-simulating sections empty with the reason.
"$armfault" report imp/replayed > report.out 2>&1; status=$?
[ $status -eq 0 ] || fail "report imp/replayed: exit $status: $(cat report.out)"
[ -s imp/replayed/report.html ] || fail "no report.html"
[ -s imp/replayed/report.md ] || fail "no report.md"
n=$(grep -o 'Empty because the runs are recorded' imp/replayed/report.html | wc -l)
[ "$n" -eq 2 ] || fail "expected the one-run and missed-runs sections empty because the runs are recorded, found $n"
grep -q 'data-plot="run-j' imp/replayed/report.html && fail "report.html plots a re-simulated run of a stand-in campaign"

# --run cannot re-simulate a recorded run: exit 2 naming --run.
"$armfault" report imp/replayed --run rig_00 -o run/report.html > run.out 2>&1; status=$?
[ $status -eq 2 ] || fail "report --run on recorded runs: exit $status, expected 2"
grep -q -- '--run' run.out || fail "report --run: the error does not name --run: $(cat run.out)"

# A preset as the twin; the recording found through replay.json.
"$armfault" report imp/replayed --twin mrr-config1 -o twin/report.html > twin.out 2>&1; status=$?
[ $status -eq 0 ] || fail "report --twin mrr-config1: exit $status: $(cat twin.out)"
grep -q '<section id="twin">' twin/report.html || fail "no twin section in report.html"
grep -q "## Twin against the recording" twin/report.md || fail "no twin table in report.md"
grep -q "imp/runs/" twin/report.md || fail "report.md does not name the recorded signals under imp/runs/"

# A results.jsonl of other data (a replay of the export) is refused, naming the file and the manifest.
"$armfault" replay sim -q -o simrep > simrep.out 2>&1 || fail "replay sim: $(tail -3 simrep.out)"
mkdir bad && cp -r imp/replayed/. bad/ && cp simrep/results.jsonl bad/
rm -f bad/report.html bad/report.md
"$armfault" report bad > bad.out 2>&1; status=$?
[ $status -eq 2 ] || fail "report of a foreign results.jsonl: exit $status, expected 2: $(cat bad.out)"
grep -q 'bad/results.jsonl: line 1: .*manifest.jsonl' bad.out || fail "the refusal does not name the line and the manifest: $(cat bad.out)"
[ -f bad/report.html ] && fail "a refused report was written"

# A replay of an export still reports (its cases are the runs) and re-simulates its run.
"$armfault" report simrep > simrep_report.out 2>&1 || fail "report of an export's replay: $(cat simrep_report.out)"
grep -q 'Empty because the runs are recorded' simrep/report.html && fail "an export's replay was treated as recorded runs"

[ $failures -eq 0 ] && echo "import replay report: all checks passed"
exit $((failures > 0))
