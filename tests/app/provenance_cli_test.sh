#!/usr/bin/env bash
# The campaign hash end to end on the command line: every shard, the merged directory and an
# unsharded run carry the same campaign_hash in summary.json and tuning.json, another campaign
# another one; `armfault report` and `armfault tune` exit 2, naming both files and what to run,
# when a directory mixes files of two campaigns. Usage: provenance_cli_test.sh path/to/armfault
# Prints one line per failed check and a final "N passed, M failed"; exits non-zero on failure.
source "$(dirname "$0")/cli_common.sh"

# The "campaign_hash" of a JSON file written with indentation.
hash_of() { sed -n 's/^ *"campaign_hash": "\(sha256:[0-9a-f]*\)".*/\1/p' "$1"; }

# A small campaign (8 runs of 2 s) with seed SEED.
campaign() {
  cat <<EOF
{"name": "prov", "seed": $1, "duration_s": 2,
 "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
 "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.5, 0.8], "onset_s": 1.0}],
 "healthy": 4, "repetitions": 2}
EOF
}
campaign 1 >"$tmp/a.json"
campaign 2 >"$tmp/b.json"
# Table 5-3 from a file, so that the report does not run the thesis experiments.
thesis='{"table_5_3": [{"kt_factor": 1.0, "thesis_pct": 80.5, "armfault_pct": 80.9, "thesis_ratio": 1, "armfault_ratio": 1, "windows": 4}]}'

run run_a "$armfault" run "$tmp/a.json" -o "$tmp/a" -j 2 -q
expect_status 0
run run_b "$armfault" run "$tmp/b.json" -o "$tmp/b" -j 2 -q
expect_status 0
for k in 0 1; do
  run "shard_$k" "$armfault" run "$tmp/a.json" -o "$tmp/s$k" --shard "$k/2" -j 2 -q
  if [[ $status -le 1 ]]; then pass; else fail "exit status $status"; fi
done
run merge "$armfault" merge "$tmp/s0" "$tmp/s1" -o "$tmp/m"
expect_status 0

# One hash for one campaign, wherever its runs ran; another for another campaign.
current=same_hash
h=$(hash_of "$tmp/a/summary.json")
if [[ $h =~ ^sha256:[0-9a-f]{64}$ ]]; then pass; else fail "a/summary.json has no campaign_hash: '$h'"; fi
for d in s0 s1 m; do
  if [[ $(hash_of "$tmp/$d/summary.json") == "$h" ]]; then pass; else fail "$d/summary.json: $(hash_of "$tmp/$d/summary.json") != $h"; fi
done
for d in a m b; do
  run "tune_$d" "$armfault" tune "$tmp/$d" -j 2 --rule youden
  expect_status 0
done
current=same_hash
for d in a m; do
  if [[ $(hash_of "$tmp/$d/tuning.json") == "$h" ]]; then pass; else fail "$d/tuning.json: $(hash_of "$tmp/$d/tuning.json") != $h"; fi
done
if [[ $(hash_of "$tmp/b/tuning.json") != "$h" && -n $(hash_of "$tmp/b/tuning.json") ]]; then pass; else
  fail "campaign b has campaign a's hash (or none)"
fi

echo "$thesis" >"$tmp/a/thesis.json"
run report_a "$armfault" report "$tmp/a"
expect_status 0
current=report_shows_hash
if grep -qF "$h" "$tmp/a/report.html" && grep -qF "$h" "$tmp/a/report.md"; then pass; else fail "report lacks $h"; fi

# tuning.json of campaign b in a's directory: refused, naming both files and what to run.
cp "$tmp/b/tuning.json" "$tmp/a/tuning.json"
run report_mixed_tuning "$armfault" report "$tmp/a"
expect_status 2
expect_stderr_contains "armfault: error: $tmp/a/tuning.json: /campaign_hash: belongs to campaign "
expect_stderr_contains "but $tmp/a/campaign.json to campaign $h"
expect_stderr_contains "run \`armfault tune $tmp/a\` to tune this directory's campaign again"
# A tuning.json without a hash (an older armfault).
sed '/"campaign_hash"/d' "$tmp/m/tuning.json" >"$tmp/a/tuning.json"
run report_old_tuning "$armfault" report "$tmp/a"
expect_status 2
expect_stderr_contains "$tmp/a/tuning.json: /campaign_hash: carries no campaign_hash"
# Re-tuning fixes it.
run retune "$armfault" tune "$tmp/a" -j 2 --rule youden
expect_status 0
run report_after_retune "$armfault" report "$tmp/a"
expect_status 0

# tune refuses a summary.json of another campaign.
cp "$tmp/b/summary.json" "$tmp/a/summary.json"
run tune_mixed_summary "$armfault" tune "$tmp/a" -j 2
expect_status 2
expect_stderr_contains "armfault: error: $tmp/a/summary.json: /campaign_hash: belongs to campaign "
expect_stderr_contains "$tmp/a/campaign.json"
run report_mixed_summary "$armfault" report "$tmp/a"
expect_status 2
expect_stderr_contains "$tmp/a/summary.json"

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
