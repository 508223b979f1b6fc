#!/usr/bin/env bash
# `armfault boundary` end to end on a small search (3 s runs, one cell, batches of 4): bad input
# is status 2 naming the file, the JSON pointer and the value; the output directory is an
# ordinary run directory (trace --run re-runs a run byte for byte, report draws the boundary,
# tune and diff read it); --from estimates from a directory's runs.
# Usage: boundary_cli_test.sh path/to/armfault
set -euo pipefail
armfault=$1
tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_boundary.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cat > "$tmp/small.json" <<'JSON'
{"name": "small-search", "seed": 5, "duration_s": 3,
 "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
 "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.8, 0.99], "onset_s": {"uniform": [0.8, 1.2]}}],
 "variation": {"torque_noise_Nm": {"uniform": [0.02, 0.06]}, "payload_kg": {"uniform": [0, 0.5]}},
 "search": {"batch": 4, "max_runs": 12}}
JSON

# Bad input: status 2, the file, the pointer and the value; nothing run.
bad() {  # NAME PYTHON-EDIT EXPECTED
  python3 -c "import json,sys; c=json.load(open(sys.argv[1])); $2; json.dump(c, open(sys.argv[2],'w'))" \
    "$tmp/small.json" "$tmp/$1.json"
  set +e
  "$armfault" boundary "$tmp/$1.json" -o "$tmp/out-$1" -q > "$tmp/$1.out" 2> "$tmp/$1.err"
  status=$?
  set -e
  [ "$status" = 2 ] || fail "$1: status $status, expected 2"
  grep -qF "$3" "$tmp/$1.err" || { cat "$tmp/$1.err" >&2; fail "$1: expected: $3"; }
  [ ! -e "$tmp/out-$1/results.jsonl" ] || fail "$1: ran anyway"
}
bad no-magnitude 'c["faults"][0]={"family":"torque_sensor_stuck","joint":3,"lead":"open","onset_s":1}' \
  "$tmp/no-magnitude.json: /faults/0/family: \"torque_sensor_stuck\" has no magnitude to search"
bad inverted 'c["search"]["range"]=[0.95,0.8]' \
  "$tmp/inverted.json: /search/range/0: inverted search range: low 0.95 is greater than high 0.8"
bad empty 'c["search"]["range"]=[0.9,0.9]' "$tmp/empty.json: /search/range: empty search range [0.9, 0.9]"
bad joint 'c["faults"][0]["joint"]=7' "$tmp/joint.json: /faults/0/joint: kt_degradation: joint 7 does not exist"
bad no-search 'del c["search"]' "$tmp/no-search.json: /search: missing: a boundary search needs a \"search\" block"

# The search, and its directory read by every other command.
"$armfault" boundary "$tmp/small.json" -o "$tmp/out" -j 2 -q > "$tmp/boundary.out"
grep -q "^trajectory .*a90/95" "$tmp/boundary.out" || fail "no table printed"
for f in boundary.json campaign.json results.jsonl decisions.jsonl summary.json junit.xml; do
  [ -s "$tmp/out/$f" ] || fail "no $f"
done
line=$(sed -n 3p "$tmp/out/results.jsonl")
run_id=$(python3 -c 'import json,sys; print(json.loads(sys.argv[1])["run_id"])' "$line")
"$armfault" trace "$tmp/out/campaign.json" --run "$run_id" -o "$tmp/trace.csv" > "$tmp/trace.out"
[ "$(grep '^record: ' "$tmp/trace.out" | cut -c9-)" = "$line" ] || fail "trace --run $run_id does not reproduce its record"
"$armfault" report "$tmp/out" > /dev/null || fail "report refused the directory"
grep -q 'id="boundary"' "$tmp/out/report.html" || fail "no boundary section in the report"
grep -q '^## Detection boundary' "$tmp/out/report.md" || fail "no boundary table in report.md"
"$armfault" tune "$tmp/out" --sweep kt_factor.worn=0.95 > /dev/null || fail "tune refused the directory"
"$armfault" diff "$tmp/out" "$tmp/out" > /dev/null || fail "diff of the directory with itself"
cp "$tmp/out/boundary.json" "$tmp/searched.json"
"$armfault" boundary --from "$tmp/out" > "$tmp/from.out" || fail "--from"
python3 - "$tmp/searched.json" "$tmp/out/boundary.json" <<'PY' || fail "--from gives another estimate"
import json, sys
a, b = (json.load(open(p))["cells"][0] for p in sys.argv[1:3])
assert a["a90_95"] == b["a90_95"] and a["runs"] == b["runs"], (a["a90_95"], b["a90_95"])
PY
# Stopped after one batch, then resumed: the same bytes as the uninterrupted search.
"$armfault" boundary "$tmp/small.json" -o "$tmp/part" -j 1 -q --max-batches 1 > "$tmp/part.out"
grep -q "^stopped after 1 batches (--max-batches); continue with: armfault boundary .* --resume" "$tmp/part.out" \
  || { cat "$tmp/part.out" >&2; fail "no stop message"; }
"$armfault" boundary "$tmp/small.json" -o "$tmp/part" -j 2 -q --resume > "$tmp/resume.out"
grep -q "([1-9][0-9]* resumed, 0 failed)" "$tmp/resume.out" || { cat "$tmp/resume.out" >&2; fail "nothing resumed"; }
for f in campaign.json results.jsonl decisions.jsonl summary.json; do
  cmp -s "$tmp/out/$f" "$tmp/part/$f" || fail "resumed $f differs from the uninterrupted search's"
done
cmp -s "$tmp/searched.json" "$tmp/part/boundary.json" || fail "resumed boundary.json differs from the uninterrupted search's"
echo "boundary cli: all checks passed"
