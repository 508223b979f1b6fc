#!/usr/bin/env bash
# Golden outputs: what users get from armfault stays byte for byte what it was. Runs the
# commands below and compares the SHA-256 of every output file (and of the stdout of the
# commands that print a record) with tests/app/golden/manifest.sha256.
#
# Usage: golden_outputs_test.sh path/to/armfault [--full] [--update]
#   --full    also the large shipped campaigns (realistic, realistic-pod, thesis-sweep):
#             minutes of CPU, for a restructuring's before/after check, not for CI
#   --update  writes the hashes of this binary into the manifest (after a change that is
#             meant to change outputs; say which figures moved and why in the commit)
#
# Exempt, because they are measurements: monitor_cost.jsonl and monitor_cost.json (times per
# tick, heap), and the wall-time lines commands print ("ran N runs in S s"); stdout is kept
# only where it is a result (trace, trace --run). Entries of the manifest that a run does not
# produce (the --full ones in CI) are skipped and counted.
set -u

if [[ $# -lt 1 || ! -x "$1" ]]; then
  echo "usage: $0 path/to/armfault [--full] [--update]" >&2
  exit 2
fi
armfault=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
shift
full=0
update=0
for a in "$@"; do
  case "$a" in
    --full) full=1 ;;
    --update) update=1 ;;
    *) echo "unknown option $a" >&2; exit 2 ;;
  esac
done
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../.." && pwd)
golden="$here/golden"
manifest="$golden/manifest.sha256"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_golden.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 2
export CI=1  # plain progress lines, never a terminal bar

errors=0
problem() {
  echo "FAIL: $*"
  errors=$((errors + 1))
}
# must NAME CMD...: runs CMD; its output goes to NAME.out/.err; a status other than 0 or 1 (a
# missed floor is a result) is a failure.
must() {
  local name=$1
  shift
  "$@" > "$tmp/$name.out" 2> "$tmp/$name.err"
  local status=$?
  if [[ $status -ne 0 && $status -ne 1 ]]; then
    problem "$name: exit status $status: $(head -c 600 "$tmp/$name.err")"
  fi
}

: > "$tmp/produced"
# record KEY FILE: the hash of FILE under KEY.
record() {
  if [[ -f "$2" ]]; then
    echo "$1 $(sha256sum < "$2" | cut -d' ' -f1)" >> "$tmp/produced"
  else
    problem "$1: $2 was not written"
  fi
}
run_files=(campaign.json results.jsonl decisions.jsonl results.csv summary.json junit.xml)
record_run() {  # KEY DIR
  for f in "${run_files[@]}"; do record "$1/$f" "$2/$f"; done
}
same_run() {  # DIR_A DIR_B WHAT
  for f in "${run_files[@]}"; do
    cmp -s "$1/$f" "$2/$f" || problem "$3: $f differs from the unsharded run's"
  done
}

cp "$golden/features.json" "$golden/wave.csv" "$golden/boundary.json" "$golden/verdicts.jsonl" "$tmp/"

# Campaign runs: every feature of a campaign file on a small one, and the shipped CI-size ones.
must features "$armfault" run features.json -o features -j 2 -q
record_run features features
must features_j1 "$armfault" run features.json -o features_j1 -j 1 -q
same_run features features_j1 "-j 1"
must shard0 "$armfault" run features.json -o shard-0 --shard 0/2 -j 1 -q
must shard1 "$armfault" run features.json -o shard-1 --shard 1/2 -j 2 -q
must merge "$armfault" merge shard-1 shard-0 -o merged
same_run features merged "merge of 2 shards"
must ci "$armfault" run "$src/campaigns/files/ci.json" -o ci -j 2 -q
record_run ci ci
must five "$armfault" run "$src/campaigns/files/five-families.json" -o five -j 2 -q
record_run five-families five
must early "$armfault" run "$src/campaigns/files/five-families.json" -o early -j 2 -q --early-stop
record_run five-families-early-stop early
record five-families-early-stop/early_stop.json early/early_stop.json
must summary_only "$armfault" run "$src/campaigns/files/ci.json" -o ci_small -j 2 -q --summary-only
for f in campaign.json results.jsonl summary.json junit.xml; do
  cmp -s "ci/$f" "ci_small/$f" || problem "--summary-only: $f differs from the full run's"
done
for f in decisions.jsonl results.csv; do
  [[ ! -e "ci_small/$f" ]] || problem "--summary-only kept $f"
done
if [[ $full -eq 1 ]]; then
  for c in realistic realistic-pod thesis-sweep; do
    must "$c" "$armfault" run "$src/campaigns/files/$c.json" -o "$c" -j 2 -q
    record_run "$c" "$c"
  done
fi

# Tuning, report and diff over those directories. campaign.json names the CSV trajectory by
# its path relative to the campaign file, so a re-simulation from the directory finds it there.
cp wave.csv features/
must tune_ci "$armfault" tune ci
record ci/tuning.json ci/tuning.json
record ci/tuned-monitor.json ci/tuned-monitor.json
must tune_features "$armfault" tune features
record features/tuning.json features/tuning.json
record features/tuned-monitor.json features/tuned-monitor.json
must report_ci "$armfault" report ci
record ci/report.html ci/report.html
record ci/report.md ci/report.md
must report_features "$armfault" report features --run "$(head -n 3 features/results.jsonl | tail -n 1 | sed 's/.*"run_id":"\([^"]*\)".*/\1/')"
record features/report.html features/report.html
record features/report.md features/report.md
must diff "$armfault" diff ci_small ci -o diff.json --markdown diff.md
record diff/diff.json diff.json
record diff/diff.md diff.md

# Thesis experiments, traces.
must thesis "$armfault" thesis -o thesis
record thesis/thesis.json thesis/thesis.json
record thesis/thesis.md thesis/thesis.md
must trace "$armfault" trace --fault '{"family":"kt_degradation","joint":3,"kt_factor":0.6,"onset_s":2}' \
  -o trace.csv --monitor-out trace_monitor.json
record trace/trace.csv trace.csv
record trace/monitor.json trace_monitor.json
record trace/stdout trace.out
compound_id=$(grep -o '"run_id":"[^"]*compound[^"]*"' features/results.jsonl | head -n 1 | cut -d'"' -f4)
must trace_run "$armfault" trace features.json --run "$compound_id" -o trace_run.csv --monitor-out trace_run_monitor.json
record trace-run/trace.csv trace_run.csv
record trace-run/monitor.json trace_run_monitor.json
record trace-run/stdout trace_run.out

# Export and offline scoring.
must export "$armfault" export "$src/campaigns/files/ci.json" -o export -j 2
record export/manifest.jsonl export/manifest.jsonl
record export/manifest.csv export/manifest.csv
for f in export/runs/*.csv.gz; do
  gzip -dc "$f" > "$tmp/one.csv" && record "$f" "$tmp/one.csv"
done
must score "$armfault" score export verdicts.jsonl -o scored
for f in results.jsonl results.csv summary.json junit.xml; do record "score/$f" "scored/$f"; done

# Boundary search.
must boundary "$armfault" boundary boundary.json -o boundary -j 2 -q
record_run boundary boundary
record boundary/boundary.json boundary/boundary.json

if [[ $update -eq 1 ]]; then
  # Keep the entries this run did not produce (the --full ones when run without it).
  { [[ -f "$manifest" ]] && grep -v -F -f <(cut -d' ' -f1 "$tmp/produced" | sed 's/$/ /') "$manifest"
    cat "$tmp/produced"; } | sort > "$tmp/manifest.new"
  cp "$tmp/manifest.new" "$manifest"
  echo "golden: wrote $(wc -l < "$manifest") hashes to $manifest"
fi

compared=0
missing=0
while read -r key hash; do
  expected=$(grep -F "$key " "$manifest" 2>/dev/null | awk -v k="$key" '$1 == k {print $2}')
  if [[ -z "$expected" ]]; then
    problem "$key: not in $manifest (run with --update to add it)"
  elif [[ "$expected" != "$hash" ]]; then
    problem "$key: output changed (sha256 $hash, golden $expected)"
  else
    compared=$((compared + 1))
  fi
done < "$tmp/produced"
missing=$(comm -23 <(cut -d' ' -f1 "$manifest" | sort) <(cut -d' ' -f1 "$tmp/produced" | sort) | wc -l)
echo "golden: $compared outputs identical, $errors problems, $missing manifest entries not produced by this run"
echo "$compared passed, $errors failed"
[[ $errors -eq 0 ]]
