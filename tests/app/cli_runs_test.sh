#!/usr/bin/env bash
# End-to-end checks of the armfault commands that run campaigns: shards, merge, kill -9 and
# --resume, Ctrl-C, trace --run, failed runs, export and score, replay, the command line's habits,
# monitor cost, robots, sensor saturation and the gearbox inputs.
# Usage: cli_runs_test.sh path/to/armfault
# Prints one line per failed check and a final "N passed, M failed"; exits non-zero on failure.
source "$(dirname "$0")/cli_common.sh"

# A small healthy campaign whose floor misses (exit 1).
printf '{"trajectories": [{"name": "a", "joints": {"3": {"type": "hold"}}}], "healthy": 2, "duration_s": 0.5,\n "floors": {"false_alarm_rate": 0, "detection_rate": 0.5}}\n' >"$tmp/healthy_only.json"

# ------------------------------------------------------------------ shards, merge, kill -9 and --resume, trace --run
ci="$src/campaigns/files/ci.json"
# same_outputs NAME DIR_A DIR_B: the output files of two run directories, byte for byte.
same_outputs() {
  current=$1
  local f
  for f in campaign.json results.jsonl decisions.jsonl results.csv summary.json junit.xml; do
    if cmp -s "$2/$f" "$3/$f"; then pass; else fail "$2/$f and $3/$f differ"; fi
  done
}
run ci_uninterrupted "$armfault" run "$ci" -o "$tmp/ci_full" -q -j 1
expect_status 0
# results.jsonl stays small (no decision statistics, under 1.5 kB a run); decisions.jsonl has
# one line per run, of the same runs in the same order.
current=results_without_decisions
if [[ $(wc -l <"$tmp/ci_full/results.jsonl") -eq 52 ]] && ! grep -q '"decision"' "$tmp/ci_full/results.jsonl" &&
  awk 'length($0) >= 1500 { bad = 1 } END { exit bad }' "$tmp/ci_full/results.jsonl"; then pass; else
  fail "results.jsonl lines carry decisions or exceed 1.5 kB: $(awk '{ print length($0) }' "$tmp/ci_full/results.jsonl" | sort -n | tail -n 1)"
fi
current=decisions_beside_results
if cmp -s <(sed 's/.*"run_id":"\([^"]*\)".*/\1/' "$tmp/ci_full/results.jsonl") \
  <(sed 's/.*"run_id":"\([^"]*\)"}$/\1/' "$tmp/ci_full/decisions.jsonl") &&
  [[ $(grep -c '^{"case_index":[0-9]*,"decision":{' "$tmp/ci_full/decisions.jsonl") -eq 52 ]]; then pass; else
  fail "decisions.jsonl does not hold the runs of results.jsonl in order: $(head -c 200 "$tmp/ci_full/decisions.jsonl")"
fi
for k in 0 1 2; do
  # A shard's own floors may miss (too few runs of a family), so only its runs are checked here.
  run "ci_shard_$k" "$armfault" run "$ci" -o "$tmp/ci_s$k" -q --shard "$k/3"
  if [[ $status -eq 0 || $status -eq 1 ]]; then pass; else fail "exit status $status; stderr: $(head -c 400 "$tmp/stderr")"; fi
done
run merge "$armfault" merge "$tmp/ci_s2" "$tmp/ci_s0" "$tmp/ci_s1" -o "$tmp/ci_merged"
expect_status 0
expect_stdout_contains "campaign ci: merged 3 shards, 52 runs -> $tmp/ci_merged"
expect_stdout_contains "floor detection_rate"
same_outputs merge_equals_unsharded "$tmp/ci_full" "$tmp/ci_merged"
run merge_missing_shard "$armfault" merge "$tmp/ci_s0" "$tmp/ci_s2" -o "$tmp/ci_m1"
expect_input_error "merge: (document root): shard 1 of 3 is missing: give the output directories of all shards 0..2"
run merge_repeated_shard "$armfault" merge "$tmp/ci_s0" "$tmp/ci_s1" "$tmp/ci_s1/" "$tmp/ci_s2" -o "$tmp/ci_m1"
expect_input_error "$tmp/ci_s1/campaign.json: /shard/index: shard 1/3 is given twice"
cp -r "$tmp/ci_s1" "$tmp/ci_s1_cut"
head -n 3 "$tmp/ci_s1/results.jsonl" >"$tmp/ci_s1_cut/results.jsonl"
run merge_incomplete_shard "$armfault" merge "$tmp/ci_s0" "$tmp/ci_s1_cut" "$tmp/ci_s2" -o "$tmp/ci_m1"
expect_input_error "$tmp/ci_s1_cut/results.jsonl: (document root): shard 1/3 is incomplete: 3 of its 17 runs, 14 missing;" \
  "--shard 1/3 -o $tmp/ci_s1_cut --resume"
run other_campaign_shard "$armfault" run "$tmp/healthy_only.json" -o "$tmp/ho_s1" -q --shard 1/3
run merge_other_campaign "$armfault" merge "$tmp/ci_s0" "$tmp/ho_s1" "$tmp/ci_s2" -o "$tmp/ci_m1"
expect_input_error "$tmp/ho_s1/campaign.json: /campaign/" "another campaign than in $tmp/ci_s0/campaign.json"
if [[ ! -e "$tmp/ci_m1/results.jsonl" ]]; then pass; else fail "a refused merge left results.jsonl behind"; fi
# A shard whose decisions.jsonl does not go with its results.jsonl (two lines swapped).
cp -r "$tmp/ci_s1" "$tmp/ci_s1_dec"
awk 'NR == 2 { held = $0; next } NR == 3 { print; print held; next } { print }' "$tmp/ci_s1/decisions.jsonl" \
  >"$tmp/ci_s1_dec/decisions.jsonl"
run merge_decisions_disagree "$armfault" merge "$tmp/ci_s0" "$tmp/ci_s1_dec" "$tmp/ci_s2" -o "$tmp/ci_m2"
expect_input_error "$tmp/ci_s1_dec/decisions.jsonl: line 2: case 7 " \
  "but line 2 of $tmp/ci_s1_dec/results.jsonl is case 4 " "decisions.jsonl does not go with results.jsonl"
if [[ ! -e "$tmp/ci_m2/results.jsonl" && ! -e "$tmp/ci_m2/decisions.jsonl" && -z $(ls "$tmp/ci_m2" 2>/dev/null | grep tmp) ]]; then
  pass
else
  fail "a refused merge left files behind: $(ls "$tmp/ci_m2")"
fi
rm "$tmp/ci_s1_dec/decisions.jsonl"
run merge_decisions_missing "$armfault" merge "$tmp/ci_s0" "$tmp/ci_s1_dec" "$tmp/ci_s2" -o "$tmp/ci_m2"
expect_input_error "$tmp/ci_s1_dec/decisions.jsonl: line 1: missing: the file does not exist"

# tune reads decisions.jsonl; an older directory's inline decisions give the same tuning.json.
run tune_new_layout "$armfault" tune "$tmp/ci_merged" -j 2
expect_status 0
mkdir "$tmp/ci_old"
cp "$tmp/ci_merged/campaign.json" "$tmp/ci_merged/summary.json" "$tmp/ci_old/"
/usr/bin/python3 - "$tmp/ci_merged" "$tmp/ci_old" <<'PY'
import json, sys
src, dst = sys.argv[1], sys.argv[2]
with open(src + "/results.jsonl") as r, open(src + "/decisions.jsonl") as d, open(dst + "/results.jsonl", "w") as out:
    for result, decision in zip(r, d):
        line = json.loads(result)
        line["decision"] = json.loads(decision)["decision"]
        out.write(json.dumps(line, sort_keys=True, separators=(",", ":")) + "\n")
PY
run tune_old_layout "$armfault" tune "$tmp/ci_old" -j 2
expect_status 0
current=tune_same_on_both_layouts
if cmp -s "$tmp/ci_merged/tuning.json" "$tmp/ci_old/tuning.json"; then pass; else fail "tuning.json differs between the layouts"; fi

# kill -9 at three points of a run, then --resume: the same bytes as the uninterrupted run.
for at in 3 14 27; do
  current=kill_at_$at
  dir="$tmp/ci_kill_$at"
  "$armfault" run "$ci" -o "$dir" -q -j 2 >/dev/null 2>&1 &
  pid=$!
  for ((i = 0; i < 1000; i++)); do  # at most ~10 s
    [[ -f "$dir/results.jsonl" && $(wc -l <"$dir/results.jsonl") -ge $at ]] && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.01
  done
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  lines=$(wc -l <"$dir/results.jsonl")
  if [[ $lines -ge $at && $lines -lt 52 ]]; then pass; else fail "killed with $lines of 52 lines written, wanted $at..51"; fi
  run "resume_after_kill_at_$at" "$armfault" run "$ci" -o "$dir" -q -j 2 --resume
  expect_status 0
  expect_stdout_contains "($lines resumed, 0 failed)"
  same_outputs "resume_after_kill_at_$at" "$tmp/ci_full" "$dir"
done

# Ctrl-C: the runs in flight finish and are kept, no summary is written, the resume command is
# printed, and running it gives the same bytes as the uninterrupted run.
# start_ci_run DIR ERR: `run` of ci.json in the background (its pid in $pid), returning once
# five runs are written.
start_ci_run() {
  "$armfault" run "$ci" -o "$1" -q -j 2 >/dev/null 2>"$2" &
  pid=$!
  for ((i = 0; i < 1000; i++)); do
    [[ -f "$1/results.jsonl" && $(wc -l <"$1/results.jsonl") -ge 5 ]] && break
    sleep 0.01
  done
}
current=ctrl_c
dir="$tmp/ci_int"
start_ci_run "$dir" "$tmp/int_err"
kill -INT "$pid"
wait "$pid"
status=$?
lines=$(wc -l <"$dir/results.jsonl")
if [[ $status -eq 130 ]]; then pass; else fail "exit status $status after SIGINT, expected 130"; fi
if [[ $lines -ge 5 && $lines -lt 52 ]]; then pass; else fail "stopped with $lines of 52 lines, wanted 5..51"; fi
if grep -qF "interrupted: kept $lines of 52 runs in $dir/results.jsonl (no summary written)" "$tmp/int_err"; then pass; else fail "stderr: $(cat "$tmp/int_err")"; fi
if grep -qF "resume with: armfault run $ci -o $dir --resume -j 2" "$tmp/int_err"; then pass; else fail "no resume command: $(cat "$tmp/int_err")"; fi
if [[ ! -e "$dir/summary.json" ]]; then pass; else fail "an interrupted run wrote summary.json"; fi
run report_of_interrupted "$armfault" report "$dir"
expect_input_error "was interrupted before its summary; finish it with \`armfault run CAMPAIGN -o $dir --resume\`"
if [[ $(tail -c 1 "$dir/results.jsonl" | od -An -c | tr -d ' ') == '\n' ]]; then pass; else fail "the last line is cut"; fi
if [[ $(wc -l <"$dir/decisions.jsonl") -eq $lines ]]; then pass; else fail "decisions.jsonl has $(wc -l <"$dir/decisions.jsonl") lines, results.jsonl $lines"; fi
run resume_after_ctrl_c "$armfault" run "$ci" -o "$dir" -q -j 2 --resume
expect_status 0
expect_stdout_contains "($lines resumed, 0 failed)"
same_outputs resume_after_ctrl_c "$tmp/ci_full" "$dir"

# A second Ctrl-C: stops at once (the runs in flight are dropped), yet never inside a run's
# lines: every line is whole, the three files agree, and --resume gives the same bytes.
current=ctrl_c_twice
dir="$tmp/ci_int2"
start_ci_run "$dir" "$tmp/int2_err"
kill -INT "$pid"
sleep 0.05
kill -INT "$pid" 2>/dev/null
wait "$pid"
status=$?
lines=$(wc -l <"$dir/results.jsonl")
if [[ $status -eq 130 ]]; then pass; else fail "exit status $status after two SIGINTs, expected 130"; fi
if grep -qF "interrupted again: stopped at once; every run written so far is kept whole in $dir/results.jsonl" "$tmp/int2_err" ||
   grep -qF "interrupted: kept $lines of 52 runs" "$tmp/int2_err"; then pass; else fail "stderr: $(cat "$tmp/int2_err")"; fi
if grep -qF "resume with: armfault run $ci -o $dir --resume -j 2" "$tmp/int2_err"; then pass; else fail "no resume command: $(cat "$tmp/int2_err")"; fi
for f in results.jsonl decisions.jsonl monitor_cost.jsonl; do
  if [[ ! -s "$dir/$f" || $(tail -c 1 "$dir/$f" | od -An -c | tr -d ' ') == '\n' ]]; then pass; else fail "the last line of $f is cut"; fi
done
if [[ $(wc -l <"$dir/decisions.jsonl") -eq $lines ]]; then pass; else fail "decisions.jsonl has $(wc -l <"$dir/decisions.jsonl") lines, results.jsonl $lines"; fi
run resume_after_ctrl_c_twice "$armfault" run "$ci" -o "$dir" -q -j 2 --resume
expect_status 0
same_outputs resume_after_ctrl_c_twice "$tmp/ci_full" "$dir"
current=ctrl_c_twice_no_lock
if [[ ! -e "$dir/.armfault.lock" ]]; then pass; else fail "the lock file stayed after the stop at once"; fi

# A full disk (here a file-size limit: the write fails with EFBIG as with ENOSPC): the run stops
# with status 2 and the reason, and no file holds half a line, the run being written taken out
# of all three; with room again, --resume gives the same bytes as the uninterrupted run.
dir="$tmp/ci_full_disk"
current=full_disk
( trap '' XFSZ; ulimit -f 200; exec "$armfault" run "$ci" -o "$dir" -q -j 1 ) >"$tmp/fd_out" 2>"$tmp/fd_err"
status=$?
if [[ $status -eq 2 ]] && grep -q "cannot write: File too large" "$tmp/fd_err"; then pass; else fail "status $status: $(cat "$tmp/fd_err")"; fi
for f in results.jsonl decisions.jsonl monitor_cost.jsonl; do
  if [[ ! -s "$dir/$f" || $(tail -c 1 "$dir/$f" | od -An -c | tr -d ' ') == '\n' ]]; then pass; else fail "the last line of $f is cut"; fi
done
lines=$(wc -l <"$dir/results.jsonl")
if [[ $lines -gt 0 && $(wc -l <"$dir/decisions.jsonl") -eq $lines && $(wc -l <"$dir/monitor_cost.jsonl") -eq $lines ]]; then pass; else
  fail "after the failed write: results $lines, decisions $(wc -l <"$dir/decisions.jsonl"), costs $(wc -l <"$dir/monitor_cost.jsonl") lines"
fi
if [[ ! -e "$dir/.armfault.lock" ]]; then pass; else fail "the lock file stayed after the full disk"; fi
run resume_after_full_disk "$armfault" run "$ci" -o "$dir" -q -j 2 --resume
expect_status 0
same_outputs resume_after_full_disk "$tmp/ci_full" "$dir"

# On a pipe, stdout and stderr reach a log in the order written: the campaign's header first,
# then the progress line, then the summary (stdout was block-buffered, so progress came first).
current=pipe_order
"$armfault" run "$ci" -o "$tmp/ci_pipe" -j 2 2>&1 | cat >"$tmp/pipe_log"
if [[ $(sed -n 1p "$tmp/pipe_log") == "campaign ci: 52 runs -> $tmp/ci_pipe" &&
      $(sed -n 2p "$tmp/pipe_log") == "progress: 52/52 runs, "* &&
      $(sed -n 3p "$tmp/pipe_log") == "ran 52 runs in "* ]]; then pass; else fail "order on a pipe: $(head -3 "$tmp/pipe_log")"; fi

# One case of the campaign re-run alone: its record is its results.jsonl line, byte for byte.
id='p2p/friction_increase#1/friction_factor=3,onset_s=U[1,3]/j3/r1'
run trace_campaign_case "$armfault" trace "$ci" --run "$id" -o "$tmp/case.csv" --monitor-out "$tmp/case.json"
expect_status 0
expect_stdout_contains "campaign ci: run $id (case 33 of 52), seed "
expect_stdout_contains "truth: friction_increase, joint 3, onset "
if cmp -s <(sed -n 's/^record: //p' "$tmp/stdout") <(grep -F "\"run_id\":\"$id\"" "$tmp/ci_full/results.jsonl"); then pass; else
  fail "the re-run's record differs from the campaign's line"
fi
if [[ $(wc -l <"$tmp/case.csv") -eq 4002 ]] && grep -q '"record": {' "$tmp/case.json"; then pass; else
  fail "trace CSV or monitor JSON not as expected"
fi
run trace_campaign_case_number "$armfault" trace "$ci" --run 33 -q -o "$tmp/case33.csv"
expect_status 0
current=trace_campaign_case_number_same
if cmp -s "$tmp/case.csv" "$tmp/case33.csv"; then pass; else fail "--run 33 and --run '$id' give different traces"; fi
run trace_campaign_unknown_id "$armfault" trace "$ci" --run 'exp1/healty/3' -q -o "$tmp/x.csv"
expect_input_error '--run: no run "exp1/healty/3" in this campaign; did you mean "exp1/healthy/3"?'
run trace_campaign_bad_case "$armfault" trace "$ci" --run 52 -q -o "$tmp/x.csv"
expect_input_error "case 52 does not exist: the campaign's cases are 0..51"
run trace_campaign_override "$armfault" trace "$ci" --run 3 --seed 2 -q -o "$tmp/x.csv"
expect_input_error "--seed, --joint and --fault do not apply"
run trace_run_without_campaign "$armfault" trace --run 3 -q -o "$tmp/x.csv"
expect_input_error "give the campaign: armfault trace CAMPAIGN.json --run RUN_ID"

# A run that diverges (its explicit viscous friction, x100 by the fault, overshoots each 1 ms
# step) is a failed record with the reason; the other runs complete; exit status 3.
printf '%s\n' '{"name": "diverge", "seed": 5, "duration_s": 1.5,' \
  ' "robot": {"modules": [{"friction": {"viscous_Nm_s_per_rad": 0.2}}], "links": [{}]},' \
  ' "trajectories": [{"name": "swing", "joints": {"1": {"type": "sine_pair", "amplitude_deg": 20, "omega_rad_s": 2}}}],' \
  ' "faults": [{"family": "friction_increase", "joint": 1, "friction_factor": [2, 100], "onset_s": 0.5}], "healthy": 2}' \
  >"$tmp/diverge.json"
run campaign_run_diverges "$armfault" run "$tmp/diverge.json" -o "$tmp/dv" -q
expect_status 3
expect_stdout_contains "ran 4 runs in "
expect_stdout_contains " (0 resumed, 1 failed)"
expect_stderr_contains "armfault: 1 of 4 runs failed (see $tmp/dv/summary.json); first failed run swing/friction_increase#0/friction_factor=100/j1/r0: simulation diverged at t=0.5"
# junit.xml fails a "failed runs" case that names the first failed run, its reason and its replay.
current=campaign_run_diverges_junit
if grep -qF '<testcase classname="failed runs" name="every run completes">' "$tmp/dv/junit.xml" &&
  grep -qF '<failure message="1 of 4 runs failed; first failed run swing/friction_increase#0/friction_factor=100/j1/r0: simulation diverged at t=0.5' "$tmp/dv/junit.xml" &&
  grep -qF "armfault trace campaign.json --run &apos;swing/friction_increase#0/friction_factor=100/j1/r0&apos;" "$tmp/dv/junit.xml"; then
  pass
else
  fail "junit.xml does not name the first failed run: $(cat "$tmp/dv/junit.xml")"
fi
if [[ $(grep -c '"status":"ok"' "$tmp/dv/results.jsonl") -eq 3 ]] &&
  grep '"status":"failed"' "$tmp/dv/results.jsonl" | grep -q '"reason":"simulation diverged at t=0.5'; then pass; else
  fail "results.jsonl lacks 3 ok runs and one diverged: $(cut -c 1-300 "$tmp/dv/results.jsonl")"
fi
if grep -q '"failed": 1,' "$tmp/dv/summary.json"; then pass; else fail "summary.json does not count the failed run"; fi
run trace_diverged_case "$armfault" trace "$tmp/diverge.json" --run 'swing/friction_increase#0/friction_factor=100/j1/r0' -o "$tmp/x.csv"
expect_status 3
expect_stdout_contains "result: failed: simulation diverged at t="

# ------------------------------------------------------------------ a unit whose commissioning fails
# A joint so viscous that the commissioning motion diverges, while the campaign only holds it:
# every run of that unit is a failed record saying why, and the command exits 3.
commfail='{"name": "commfail", "seed": 1, "duration_s": 1,
 "robot": {"modules": [{"friction": {"viscous_Nm_s_per_rad": 10}}], "links": [{}]},
 "trajectories": [{"name": "still", "joints": {"1": {"type": "hold", "angle_deg": 0}}}],
 "healthy": 2, "commissioning": COMMISSIONING, "variation": {"units": 1}}'
echo "${commfail/COMMISSIONING/true}" >"$tmp/commfail.json"
echo "${commfail/COMMISSIONING/false}" >"$tmp/commok.json"
run commissioning_fails "$armfault" run "$tmp/commfail.json" -o "$tmp/cf" -q
expect_status 3
if [[ $(grep -c '"reason":"the commissioning run of unit 0 failed: simulation diverged at t=' "$tmp/cf/results.jsonl") -eq 2 ]]; then
  pass
else
  fail "results.jsonl lacks two runs failed by their unit's commissioning: $(cut -c 1-300 "$tmp/cf/results.jsonl")"
fi
run commissioning_off_runs "$armfault" run "$tmp/commok.json" -o "$tmp/cok" -q
expect_status 0
# Every run failed, with floors: each floor says so and names the first failure (it used to say
# "no faulty runs, nothing to measure"), is missed, and the console names the first failure.
echo "${commfail/COMMISSIONING/true}" | sed 's/"healthy": 2,/"healthy": 2, "floors": {"detection_rate": 0.9, "false_alarm_rate": 0.1},/' \
  >"$tmp/commfail_floors.json"
run all_runs_failed_floors "$armfault" run "$tmp/commfail_floors.json" -o "$tmp/cff" -q
expect_status 3
expect_stdout_contains "floor false_alarm_rate"
expect_stdout_contains "MISSED  false_alarm_rate: all 2 runs failed, nothing to measure (floor <= 0.100); first failed run still/healthy/0: the commissioning run of unit 0 failed: simulation diverged at t="
expect_stderr_contains "armfault: 2 of 2 runs failed (see $tmp/cff/summary.json); first failed run still/healthy/0: the commissioning run of unit 0 failed: "
current=all_runs_failed_floors_output
if grep -q 'no faulty runs\|no healthy runs' "$tmp/stdout" "$tmp/cff/summary.json" "$tmp/cff/junit.xml"; then
  fail "a floor still says there were no runs: $(grep -h 'no faulty runs\|no healthy runs' "$tmp/stdout" "$tmp/cff/summary.json")"
elif grep -q '"floors_met": false' "$tmp/cff/summary.json" && grep -qF 'all 2 runs failed' "$tmp/cff/junit.xml"; then
  pass
else
  fail "summary.json or junit.xml does not fail the floors of a campaign whose every run failed"
fi

# ------------------------------------------------------------------ export and score
cat >"$tmp/exp.json" <<'JSON'
{"name": "exp", "seed": 2, "duration_s": 3,
 "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
 "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": 1.0}],
 "healthy": 1, "floors": {"detection_rate": 0.9}}
JSON
run export_writes_signals_and_manifest "$armfault" export "$tmp/exp.json" -o "$tmp/exp" --split 0.5/0.25/0.25 -q
expect_status 0
if [[ -f "$tmp/exp/runs/000000.csv.gz" && -f "$tmp/exp/runs/000001.csv.gz" && $(wc -l <"$tmp/exp/manifest.jsonl") -eq 2 ]] &&
  zcat "$tmp/exp/runs/000000.csv.gz" | head -1 | grep -q "^t_s,q_ref_rad_j1,"; then pass; else
  fail "export did not write two runs and a manifest: $(ls -R "$tmp/exp" | head -20)"
fi
# channels.json describes the runs' columns, in order: every one a sensor's (what a monitor reads).
if python3 -c 'import json,sys; c=json.load(open(sys.argv[1])); h=sys.stdin.readline().strip().split(","); sys.exit(not (c["file"]=="runs/*.csv.gz" and [x["name"] for x in c["channels"]]==h and {x["source"] for x in c["channels"]}=={"sensor"} and c["channels"][5]["unit"]=="N m"))' \
    "$tmp/exp/channels.json" < <(zcat "$tmp/exp/runs/000000.csv.gz" | head -1); then pass; else
  fail "export's channels.json does not describe runs/*.csv.gz"
fi
# No verdict at all: the fault is missed, the floor fails (exit 1) as it would in `run`.
: >"$tmp/none.jsonl"
run score_without_verdicts_misses_the_floor "$armfault" score "$tmp/exp" "$tmp/none.jsonl" -o "$tmp/scored"
expect_status 1
expect_stdout_contains "floor detection_rate"
expect_stdout_contains "next: armfault report $tmp/scored"
id=$(head -1 "$tmp/exp/manifest.jsonl" | sed 's/.*"run_id":"\([^"]*\)".*/\1/')
printf '{"run_id": "%s", "t_s": 1.5, "joint": 3, "family": "kt_degradation", "alarm": true, "magnitude": 0.6}\n' "$id" >"$tmp/one.jsonl"
run score_meets_the_floor "$armfault" score "$tmp/exp" "$tmp/one.jsonl" -o "$tmp/scored"
expect_status 0
# The scored directory's monitor is the verdicts file (as given, with its SHA-256): diff of the
# live run and the scored verdicts says the monitor differs; tune refuses verdicts.
current=score_records_the_verdicts_as_its_monitor
want="{\"file\":\"$tmp/one.jsonl\",\"sha256\":\"$(sha256sum "$tmp/one.jsonl" | cut -d' ' -f1)\",\"type\":\"verdicts\"}"
got=$(python3 -c 'import json,sys; print(json.dumps(json.load(open(sys.argv[1]))["campaign"]["monitor"], sort_keys=True, separators=(",", ":")))' "$tmp/scored/campaign.json")
got_summary=$(python3 -c 'import json,sys; print(json.dumps(json.load(open(sys.argv[1]))["campaign"]["monitor"], sort_keys=True, separators=(",", ":")))' "$tmp/scored/summary.json")
if [[ "$got" == "$want" && "$got_summary" == "$want" ]]; then pass; else fail "campaign.json monitor $got, summary.json $got_summary, expected $want"; fi
run score_run_of_the_export "$armfault" run "$tmp/exp.json" -o "$tmp/exprun" -q
run diff_of_live_and_scored_says_the_monitor_differs "$armfault" diff "$tmp/exprun" "$tmp/scored"
expect_stdout_contains "the campaigns differ in: monitor; comparisons are by group key"
run tune_refuses_scored_verdicts "$armfault" tune "$tmp/scored"
expect_input_error "$tmp/scored/campaign.json: /campaign/monitor/type: a directory of armfault score (verdicts of $tmp/one.jsonl): verdicts cannot be re-thresholded; tune the detector that wrote them"
printf '{"run_id": "%s", "t_s": 7, "joint": 3, "family": "kt_degradation", "alarm": true, "magnitude": 0.6}\n' "$id" >"$tmp/late.jsonl"
run score_rejects_a_time_outside_the_run "$armfault" score "$tmp/exp" "$tmp/late.jsonl" -o "$tmp/scored2"
expect_input_error "$tmp/late.jsonl: line 1: t_s 7 outside the run [0, 3] s"
# Every bad line at once (up to 20, then how many more), in one error (exit 2): a run_id with a
# typo names the nearest one; Python's NaN is explained; 23 more bad lines after those.
{
  printf '{"run_id": "%sx", "t_s": 1.5, "joint": 3, "alarm": false}\n' "$id"
  printf '{"run_id": "%s", "t_s": 1.5, "joint": 3, "alarm": true, "family": "kt_degradation", "magnitude": NaN}\n' "$id"
  for k in $(seq 1 23); do printf '{"run_id": "%s", "t_s": 1.5, "joint": 9, "alarm": false}\n' "$id"; done
} >"$tmp/many_bad.jsonl"
run score_lists_every_bad_line "$armfault" score "$tmp/exp" "$tmp/many_bad.jsonl" -o "$tmp/scored3"
expect_status 2
expect_stderr_contains "armfault: error: $tmp/many_bad.jsonl: line 1: unknown run_id \"${id}x\" (not a run of $tmp/exp/manifest.jsonl); did you mean \"$id\"?"
expect_stderr_contains "armfault: error: $tmp/many_bad.jsonl: line 2: /magnitude: NaN is not JSON; write null (Python's json.dumps writes float(\"nan\") as NaN"
expect_stderr_contains "armfault: error: $tmp/many_bad.jsonl: line 20: joint 9 out of range, expected 1..3"
expect_stderr_contains "armfault: error: ... and 5 more errors"
current=score_lists_every_bad_line_count
if [[ $(grep -c '^armfault: error: ' "$tmp/stderr") -eq 21 && ! -e "$tmp/scored3/results.jsonl" ]]; then pass; else
  fail "expected 20 error lines and the 'more' line, and nothing written: $(head -c 600 "$tmp/stderr")"
fi
run export_rejects_a_bad_split "$armfault" export "$tmp/exp.json" -o "$tmp/exp2" --split 0.9/0.2/0.1 -q
expect_input_error "armfault: error: --split: expected TRAIN/VALIDATION/TEST fractions summing to 1"

# ------------------------------------------------------------------ replay
# The export's signals through the campaign's own monitor: the run's results, line for line, the
# floors and exit status of `run`, and the false alarms per hour of operation.
run replay_is_the_run "$armfault" replay "$tmp/exp" -o "$tmp/replayed" -j 2 -q
expect_status 0
expect_stdout_contains "floor detection_rate"
expect_stdout_contains "alarms per hour of operation: 0 (95 % upper bound 3595): 0 alarm onsets in 0.0008333 h of 1 healthy and 0 unlabelled runs"
current=replay_results_are_the_runs
if cmp -s "$tmp/replayed/results.jsonl" "$tmp/exprun/results.jsonl" && cmp -s "$tmp/replayed/decisions.jsonl" "$tmp/exprun/decisions.jsonl" &&
  python3 -c 'import json,sys; a=json.load(open(sys.argv[1]))["alarms_per_hour"]; sys.exit(not (a["healthy_runs"]==1 and a["alarm_onsets"]==0))' "$tmp/replayed/summary.json"; then pass; else
  fail "replayed results.jsonl differ from the run's: $(diff "$tmp/replayed/results.jsonl" "$tmp/exprun/results.jsonl" | head -c 400)"
fi
run replay_report_reads_it "$armfault" report "$tmp/replayed"
expect_status 0
run replay_of_no_directory "$armfault" replay "$tmp/nope" -o "$tmp/r2"
expect_input_error "armfault: error: $tmp/nope: (document root): no such directory"
run replay_of_a_run_directory "$armfault" replay "$tmp/exprun" -o "$tmp/r2"
expect_input_error "armfault: error: $tmp/exprun/manifest.jsonl: (document root): missing: replay reads an export's or an import's manifest.jsonl"
printf '{"type": "power_efficency"}\n' >"$tmp/m.json"
run replay_names_a_bad_monitor_file "$armfault" replay "$tmp/exp" --monitor "$tmp/m.json" -o "$tmp/r2"
expect_input_error "armfault: error: $tmp/m.json: /type: "
run replay_commission_names_the_nearest_run "$armfault" replay "$tmp/exp" --commission exp1/helthy/0 -o "$tmp/r2"
expect_input_error "armfault: error: --commission: unknown run \"exp1/helthy/0\"" "did you mean \"exp1/healthy/0\"?"

# ------------------------------------------------------------------ habits of the command line
run usage_names_the_program "$armfault" --help
expect_status 0
expect_stdout_contains "Usage: armfault [OPTIONS] SUBCOMMAND"
run unknown_command "$armfault" rn
expect_status 2
expect_stderr_contains 'armfault: unknown command "rn"; did you mean "run"?'
current=unknown_command_hint_first
if [[ $(head -n 1 "$tmp/stderr") == 'armfault: unknown command "rn"; did you mean "run"?' ]] && ! grep -q "A subcommand is required" "$tmp/stderr"; then
  pass
else
  fail "the hint is not first, or CLI11's message misleads: $(cat "$tmp/stderr")"
fi
for cmd in run trace tune diff report validate; do
  run "help_exit_codes_$cmd" "$armfault" $cmd --help
  expect_stdout_contains "Exit status: 0 done"
  expect_stdout_contains "130 interrupted"
done
run unknown_option "$armfault" run --jbos 2
expect_status 2
expect_stderr_contains "armfault run: unknown option --jbos; did you mean --jobs?"
run shard_count_without_index env -u JOB_COMPLETION_INDEX -u SLURM_ARRAY_TASK_ID "$armfault" run --shard-count 4 -o "$tmp/sc" -q
expect_input_error "armfault: error: --shard-count: gives N with the shard index from JOB_COMPLETION_INDEX, which is not set"
run shard_and_shard_count env -u JOB_COMPLETION_INDEX -u SLURM_ARRAY_TASK_ID "$armfault" run --shard 0/2 --shard-count 2 -o "$tmp/sc" -q
expect_input_error "armfault: error: --shard-count: --shard K/N already gives the count"
run run_says_what_next "$armfault" run "$src/campaigns/files/thesis-sweep.json" -o "$tmp/next" -j 2
expect_stdout_contains "next: armfault report $tmp/next"
expect_stdout_contains "armfault tune $tmp/next"
expect_stdout_contains "wrote $tmp/next/results.jsonl, decisions.jsonl, results.csv, summary.json, junit.xml"

# --summary-only (small CI artefacts): exactly campaign.json, results.jsonl, summary.json and
# junit.xml are left, the same bytes as a full run's; report and diff work on them, tune
# says why it cannot.
run help_run "$armfault" run --help
expect_stdout_contains "--summary-only"
expect_stdout_contains "decisions.jsonl"
run summary_only "$armfault" run "$ci" -o "$tmp/ci_summary" -j 2 --summary-only
expect_status 0
expect_stdout_contains "wrote $tmp/ci_summary/results.jsonl, summary.json, junit.xml, monitor_cost.json (--summary-only: decisions.jsonl, results.csv and monitor_cost.jsonl removed)"
expect_stdout_contains "next: armfault report $tmp/ci_summary"
current=summary_only_no_tune_hint
if grep -q "armfault tune" "$tmp/stdout"; then fail "suggests tune without decisions: $(cat "$tmp/stdout")"; else pass; fi
current=summary_only_files
if [[ $(cd "$tmp/ci_summary" && ls | tr '\n' ' ') == "campaign.json junit.xml monitor_cost.json results.jsonl summary.json " ]]; then pass; else
  fail "left $(ls "$tmp/ci_summary" | tr '\n' ' ')"
fi
for f in campaign.json results.jsonl summary.json junit.xml; do
  if cmp -s "$tmp/ci_full/$f" "$tmp/ci_summary/$f"; then pass; else fail "$f differs from the full run's"; fi
done
run summary_only_tune "$armfault" tune "$tmp/ci_summary" -j 2
expect_input_error "$tmp/ci_summary/results.jsonl: line 1: no decision statistics: $tmp/ci_summary/decisions.jsonl does not exist"
run summary_only_diff "$armfault" diff "$tmp/ci_full" "$tmp/ci_summary"
expect_status 0
# A stale results.csv or decisions.jsonl of an earlier run in the directory goes too.
cp "$tmp/ci_full/results.csv" "$tmp/ci_full/decisions.jsonl" "$tmp/ci_summary/"
run summary_only_again "$armfault" run "$tmp/healthy_only.json" -o "$tmp/ci_summary" -q --summary-only --force
current=summary_only_stale
if [[ ! -e "$tmp/ci_summary/results.csv" && ! -e "$tmp/ci_summary/decisions.jsonl" ]]; then pass; else fail "stale files kept"; fi

# Output directories: another campaign's results are kept (exit 2) unless --force; the same
# campaign again is a rerun; a symbolic link is refused; no lock file is left after any exit.
mkdir -p "$tmp/keep" && cp "$tmp/ci_full/campaign.json" "$tmp/ci_full/results.jsonl" "$tmp/keep/"
before=$(sha256sum "$tmp/keep/results.jsonl")
run other_campaign_kept "$armfault" run "$tmp/healthy_only.json" -o "$tmp/keep" -q
expect_input_error "$tmp/keep: (document root): holds the results of campaign \"ci\"; they are kept: --resume continues only the same campaign and shard, --force replaces them"
current=other_campaign_kept_bytes
if [[ $(sha256sum "$tmp/keep/results.jsonl") == "$before" ]]; then pass; else fail "results.jsonl of the other campaign changed"; fi
current=other_campaign_kept_no_lock
if [[ ! -e "$tmp/keep/.armfault.lock" ]]; then pass; else fail "the lock file stayed after exit 2"; fi
run other_shard_kept "$armfault" run "$ci" -o "$tmp/keep" -q --shard 1/2
expect_input_error "$tmp/keep: (document root): holds the results of campaign \"ci\" (another shard)"
# (healthy_only.json's detection floor has no faults to meet: status 1, a result)
run other_campaign_forced "$armfault" run "$tmp/healthy_only.json" -o "$tmp/keep" -q --force
expect_status 1
run same_campaign_rerun "$armfault" run "$tmp/healthy_only.json" -o "$tmp/keep" -q
expect_status 1
current=rerun_no_lock
if [[ ! -e "$tmp/keep/.armfault.lock" ]]; then pass; else fail "the lock file stayed after a run"; fi
ln -s "$tmp/keep" "$tmp/keep_link"
run output_dir_symlink "$armfault" run "$tmp/healthy_only.json" -o "$tmp/keep_link" -q
expect_input_error "$tmp/keep_link: (document root): the output directory is a symbolic link"
# junit.xml: a case per group and trajectory, and its failure replays the first wrong run.
if grep -q '<testsuite name="kt_degradation" tests=' "$tmp/next/junit.xml" &&
  grep -q '<testcase classname="healthy" name="exp1: healthy runs">' "$tmp/next/junit.xml"; then pass; else
  fail "junit.xml lacks the per-family suites: $(head -c 400 "$tmp/next/junit.xml")"
fi

# Monitor cost (campaigns/running/monitor_cost.h): one line per run in monitor_cost.jsonl, the campaign's
# in monitor_cost.json, and a floor on the mean time per tick that sets the exit status.
printf '{"trajectories": [{"name": "a", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 1}}}],
 "healthy": 3, "duration_s": 0.5, "floors": {"false_alarm_rate": 0.5, "monitor_us_per_tick": %s}}
' 0.000001 >"$tmp/cost_low.json"
run monitor_cost_floor_missed "$armfault" run "$tmp/cost_low.json" -o "$tmp/cost_low" -q
expect_status 1
expect_stdout_contains "floor monitor_us_per_tick"
expect_stdout_contains "MISSED  monitor_us_per_tick"
current=monitor_cost_files
if [[ $(wc -l <"$tmp/cost_low/monitor_cost.jsonl") -eq 3 ]] && grep -q '"ticks":251' "$tmp/cost_low/monitor_cost.jsonl" &&
  grep -q '"mean_us_per_tick"' "$tmp/cost_low/monitor_cost.json" && grep -q '"heap_bytes": [0-9]' "$tmp/cost_low/monitor_cost.json" &&
  ! grep -q 'monitor_us_per_tick' "$tmp/cost_low/junit.xml"; then pass; else
  fail "monitor_cost files: $(cat "$tmp/cost_low/monitor_cost.json" | head -c 600)"
fi
sed 's/"monitor_us_per_tick": 0.000001/"monitor_us_per_tick": 100000/' "$tmp/cost_low.json" >"$tmp/cost_high.json"
run monitor_cost_floor_met "$armfault" run "$tmp/cost_high.json" -o "$tmp/cost_high" -q
expect_status 0
expect_stdout_contains "met     monitor_us_per_tick"
sed 's/"monitor_us_per_tick": 0.000001/"monitor_us_per_tick": 0/' "$tmp/cost_low.json" >"$tmp/cost_zero.json"
run monitor_cost_floor_zero "$armfault" run "$tmp/cost_zero.json" -o "$tmp/cost_zero" -q
expect_input_error "$tmp/cost_zero.json: /floors/monitor_us_per_tick: expected the monitor's mean time per tick in microseconds, > 0, got 0"


# `armfault robot`: a robot in full; written as a URDF and read back, the same plant:
# the ci campaign on mrr-config1 from its written URDF detects and names exactly the same runs.
run robot_full "$armfault" robot ur-class
expect_status 0
expect_stdout_contains '"joint_name": "wrist_3"'
run robot_unknown "$armfault" robot nope
expect_input_error '<command line>: robot: "nope" is neither a robot preset (mrr-config1, pendulum, ur-class) nor a file'
mkdir -p "$tmp/urdf_rt"
run robot_urdf "$armfault" robot mrr-config1 --urdf "$tmp/urdf_rt"
expect_status 0
/usr/bin/python3 - "$src/campaigns/files/ci.json" "$tmp/urdf_rt/mrr-config1.robot.json" "$tmp/urdf_rt/ci-urdf.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1])); c["robot"] = json.load(open(sys.argv[2])); c["name"] = "ci"
json.dump(c, open(sys.argv[3], "w"))
PY
run robot_urdf_ci "$armfault" run "$tmp/urdf_rt/ci-urdf.json" -o "$tmp/urdf_rt/out" -q -j 2
expect_status 0
run robot_preset_ci "$armfault" run "$src/campaigns/files/ci.json" -o "$tmp/urdf_rt/ref" -q -j 2
current=robot_urdf_same_detections
if diff <(cut -d, -f2,17,21,22,23 "$tmp/urdf_rt/ref/results.csv") <(cut -d, -f2,17,21,22,23 "$tmp/urdf_rt/out/results.csv") >"$tmp/urdf_diff"; then pass; else
  fail "the written URDF's ci results differ: $(head -c 600 "$tmp/urdf_diff")"
fi


# Sensor saturation: a motion whose torque goes beyond a joint's sensor is recorded
# (sensor_saturated_s) and warned about, and its healthy runs raise no stuck-sensor alarm.
/usr/bin/python3 - "$tmp/saturating.json" <<'PY'
import json, subprocess, sys
robot = {"name": "sat", "modules": [{"type": "MRR1"}, {}, {"torque_sensor": {"full_scale_Nm": 2.3}}],
         "links": [{"mass_kg": 2.5, "length_m": 0.2, "radius_m": 0.05, "direction": [0, 0, 1], "joint_axis": [0, 0, 1]},
                   {"mass_kg": 1.8, "length_m": 0.3, "radius_m": 0.045, "direction": [0, 0, 1], "joint_axis": [0, -1, 0]},
                   {"mass_kg": 1.0, "length_m": 0.25, "radius_m": 0.035, "direction": [1, 0, 0], "joint_axis": [0, -1, 0]}],
         "base_position_m": [0, 0, 0.15], "payload_kg": 2.0}
c = {"name": "sat", "robot": robot, "duration_s": 8, "healthy": 2, "floors": {"false_alarm_rate": 0.0},
     "trajectories": [{"name": "lower", "joints": {"3": {"type": "min_jerk", "waypoints": [[0, 60], [1, 60], [4, 0], [8, 0]]}}}]}
json.dump(c, open(sys.argv[1], "w"))
PY
run saturation_warned "$armfault" run "$tmp/saturating.json" -o "$tmp/saturating" -q
expect_status 0
expect_stderr_contains "armfault: warning: joint 3's torque went beyond its torque sensor's range in 2 of 2 runs"
current=saturation_recorded
if [[ $(grep -c '"sensor_saturated_s":{"3":' "$tmp/saturating/results.jsonl") -eq 2 ]] &&
  ! grep -q sensor_saturated_s "$tmp/urdf_rt/ref/results.jsonl"; then pass; else
  fail "sensor_saturated_s: $(head -c 600 "$tmp/saturating/results.jsonl")"
fi


# The report's thesis table is about mrr-config1's top joint: not shown for another robot.
printf '{"robot": "ur-class", "duration_s": 1, "healthy": 1, "trajectories": [{"name": "a", "joints": {"2": {"type": "sine_pair", "amplitude_deg": 5, "omega_rad_s": 1}}}]}\n' >"$tmp/ur_tiny.json"
run ur_tiny "$armfault" run "$tmp/ur_tiny.json" -o "$tmp/ur_tiny" -q
expect_status 0
run report_no_thesis "$armfault" report "$tmp/ur_tiny"
expect_status 0
current=report_no_thesis_table
if grep -q "not shown: the thesis&#39;s table is about mrr-config1&#39;s top joint" "$tmp/ur_tiny/report.html"; then pass; else
  fail "the ur-class report shows the thesis table"
fi


# Without a torque sensor: the sensor's families are input errors on that joint, a bad value of
# "torque_sensor" names the drive, and a run reads NaN where the sensor would be.
cp "$src/campaigns/files/robots/ur-class.urdf" "$tmp/ur-class.urdf"
printf '{"robot": {"urdf": "ur-class.urdf", "drives": {"shoulder_pan": "industrial-large", "shoulder_lift": {"type": "industrial-large", "torque_sensor": null}, "elbow": "industrial-large", "wrist_1": "industrial-small", "wrist_2": "industrial-small", "wrist_3": "industrial-small"}}, "duration_s": 2, "healthy": 1, "faults": [{"family": "torque_sensor_stuck", "joint": [1, 2], "lead": "supply", "onset_s": 1}], "trajectories": [{"name": "a", "joints": {"2": {"type": "sine_pair", "amplitude_deg": 5, "omega_rad_s": 1}}}]}\n' >"$tmp/no_sensor.json"
run no_sensor_family "$armfault" validate "$tmp/no_sensor.json"
expect_input_error 'no_sensor.json: /faults/0/joint/1: torque_sensor_stuck: joint 2 (shoulder_lift) has no torque sensor (robot ur-class): this family needs one'
sed 's/"torque_sensor": null/"torque_sensor": "none"/' "$tmp/no_sensor.json" >"$tmp/no_sensor_bad.json"
run no_sensor_bad_value "$armfault" validate "$tmp/no_sensor_bad.json"
expect_input_error '/robot/drives/shoulder_lift/torque_sensor: expected an object (the sensor'"'"'s parameters) or null (no torque sensor), got string "none"'
printf '{"robot": {"urdf": "ur-class.urdf", "drives": {"shoulder_pan": "industrial-large", "shoulder_lift": {"type": "industrial-large", "torque_sensor": null}, "elbow": "industrial-large", "wrist_1": "industrial-small", "wrist_2": "industrial-small", "wrist_3": "industrial-small"}}, "duration_s": 0.1, "joints": {"2": {"type": "sine_pair", "amplitude_deg": 5, "omega_rad_s": 1}}}\n' >"$tmp/no_sensor_run.json"
run no_sensor_trace "$armfault" trace "$tmp/no_sensor_run.json" -o "$tmp/no_sensor_trace.csv"
expect_status 0
current=no_sensor_reads_nan
if [[ $(awk -F, 'NR==1 { for (i = 1; i <= NF; i++) if ($i == "tau_sensor_Nm_j2") c = i } NR == 3 { print $c }' "$tmp/no_sensor_trace.csv") == nan ]]; then pass; else
  fail "tau_sensor_Nm_j2 of a joint without a sensor: $(sed -n 3p "$tmp/no_sensor_trace.csv" | head -c 300)"
fi


# export shows the same progress line as run (rate and time left).
run export_progress "$armfault" export "$tmp/exp.json" -o "$tmp/exp_progress"
expect_status 0
current=export_progress_line
if grep -Eq '^progress: ([0-9]+)/\1 runs, [0-9.]+ runs/s, [0-9]+ s left$' "$tmp/stderr"; then pass; else
  fail "export's progress line: $(head -c 400 "$tmp/stderr")"
fi


# Bad robot inputs: each names the field and the value, exit 2.
: >"$tmp/not_a_dir"
run robot_urdf_not_a_dir "$armfault" robot mrr-config1 --urdf "$tmp/not_a_dir"
expect_input_error "--urdf: \"$tmp/not_a_dir\" exists and is not a directory"
printf '{"robot": {"modules": [{}], "bodies": []}, "duration_s": 1}\n' >"$tmp/empty_bodies.json"
run robot_empty_bodies "$armfault" trace "$tmp/empty_bodies.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/empty_bodies.json: /robot/bodies: expected one body per module, got an empty array"
printf '{"robot": {"urdf": "missing.urdf", "drives": {}}, "duration_s": 1}\n' >"$tmp/missing_urdf.json"
run robot_missing_urdf "$armfault" trace "$tmp/missing_urdf.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/missing_urdf.json: /robot/urdf: cannot read the URDF file \"$tmp/missing.urdf\": No such file or directory"

# Bad gearbox, cycle and start inputs: each names the file, the field and the value, exit 2.
gear_run() {  # $1: the module's JSON; $2: extra run keys; $3: joint 3's trajectory (default: hold)
  local trajectory='{"type": "hold"}'
  [[ -n ${3:-} ]] && trajectory=$3
  printf '{"robot": {"modules": [{"type": "MRR1"}, {}, %s], "links": [{"direction": [0, 0, 1], "joint_axis": [0, 0, 1]}, {"direction": [0, 0, 1], "joint_axis": [0, -1, 0]}, {"joint_axis": [0, -1, 0]}]}, "duration_s": 0.1%s, "joints": {"3": %s}}\n' "$1" "${2:-}" "$trajectory"
}
gear_run '{"gearbox": {"thermal_resistance_K_per_W": -1}}' >"$tmp/gear_negative.json"
run gearbox_negative "$armfault" trace "$tmp/gear_negative.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/gear_negative.json: /robot/modules/2/gearbox/thermal_resistance_K_per_W: -1 must be greater than 0"
gear_run '{"gearbox": {"vogel_C_C": 1e999}}' >"$tmp/gear_huge.json"
run gearbox_huge "$armfault" trace "$tmp/gear_huge.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/gear_huge.json: /robot/modules/2/gearbox/vogel_C_C: the number 1e999 is beyond the range of a double"
gear_run '{"gearbox": {"load_friction_backdriven": 2}}' >"$tmp/gear_range.json"
run gearbox_out_of_range "$armfault" trace "$tmp/gear_range.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/gear_range.json: /robot/modules/2/gearbox/load_friction_backdriven: 2 is outside [0, 0.9]"
gear_run '{"gearbox": {"sensor_gain_per_K": "0.001"}}' >"$tmp/gear_type.json"
run gearbox_wrong_type "$armfault" trace "$tmp/gear_type.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/gear_type.json: /robot/modules/2/gearbox/sensor_gain_per_K: expected a number, got string \"0.001\""
gear_run '{"gearbox": {"vogel_B_K": 4000}}' >"$tmp/gear_vogel.json"
run gearbox_vogel_extreme "$armfault" trace "$tmp/gear_vogel.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/gear_vogel.json: /robot/modules/2/gearbox/vogel_B_K: vogel_B_K 4000 K with vogel_C_C -100 C scales friction by"
gear_run '{}' ', "start": "lukewarm"' >"$tmp/start_bad.json"
run start_unknown "$armfault" trace "$tmp/start_bad.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/start_bad.json: /start: unknown start \"lukewarm\" (known: cold, warm)"
gear_run '{}' ', "start": "wram"' >"$tmp/start_typo.json"
run start_typo "$armfault" trace "$tmp/start_typo.json" -o "$tmp/x.csv" -q
expect_status 2
gear_run '{}' ', "start": "Warm"' >"$tmp/start_case.json"
run start_case "$armfault" trace "$tmp/start_case.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/start_case.json: /start: unknown start \"Warm\" (known: cold, warm); did you mean \"warm\"?"
gear_run '{}' '' '{"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 2, "cycle": true, "cycle_period_s": 2}' >"$tmp/cycle_open.json"
run cycle_not_closed "$armfault" trace "$tmp/cycle_open.json" -o "$tmp/x.csv" -q
expect_input_error "$tmp/cycle_open.json: /joints/3/cycle: the cycle does not return to its start after cycle_period_s = 2 s" "mismatch"
gear_run '{"type": "industrial-small-thermal", "min_angle_deg": -120, "max_angle_deg": 120}' ', "start": "warm"' '{"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 2, "cycle": true, "cycle_period_s": 3.141592653589793}' >"$tmp/cycle_ok.json"
run cycle_warm_ok "$armfault" trace "$tmp/cycle_ok.json" -o "$tmp/x.csv" -q
expect_status 0

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
