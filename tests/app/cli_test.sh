#!/usr/bin/env bash
# End-to-end checks of the armfault command line: usage, input errors, trace output, run files,
# faults, monitor, thesis, campaign errors and diff (the runs themselves: cli_runs_test.sh).
# Usage: cli_test.sh path/to/armfault
# Prints one line per failed check and a final "N passed, M failed"; exits non-zero on failure.
source "$(dirname "$0")/cli_common.sh"

# ------------------------------------------------------------------ usage

run version "$armfault" --version
expect_status 0
expect_stdout_contains "armfault 0."

run help "$armfault" --help
expect_status 0
expect_stdout_contains "trace"

run no_subcommand "$armfault"
expect_status 2

run unknown_subcommand "$armfault" frobnicate
expect_status 2

run bad_flag "$armfault" trace --no-such-flag
expect_status 2
expect_stderr_contains "--no-such-flag"

run bad_duration_text "$armfault" trace --duration abc
expect_status 2

run missing_flag_value "$armfault" trace --robot
expect_status 2

# ------------------------------------------------------------------ invalid input

run unknown_preset "$armfault" trace --robot nope -q -o "$tmp/x.csv"
expect_input_error 'unknown robot preset "nope"' \
  'armfault: error: <command line>: /robot: unknown robot preset "nope" (known: mrr-config1, pendulum, ur-class)'

printf '{"robot": "mrr-config1", "duraton_s": 1}\n' >"$tmp/unknown_key.json"
run unknown_key "$armfault" trace "$tmp/unknown_key.json" -q -o "$tmp/x.csv"
expect_input_error "armfault: error: $tmp/unknown_key.json: /duraton_s: unknown key \"duraton_s\""

printf '{"duration_s": 1, "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega": 1}}}\n' \
  >"$tmp/nested_key.json"
run nested_unknown_key "$armfault" trace "$tmp/nested_key.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/nested_key.json: /joints/3/omega: unknown key \"omega\""

printf '{"duration_s": 1, "robot": {"modules": [{}, {"motor": {"kt_Nm_per_A": -1}}], "links": [{}, {}]}}\n' \
  >"$tmp/bad_robot.json"
run bad_robot_value "$armfault" trace "$tmp/bad_robot.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/bad_robot.json: /robot/modules/1/motor/kt_Nm_per_A: -1 must be greater than 0"
# The optional ripple group (core/plant/parts/torque_ripple.h): out of range, beyond a double, wrong type.
printf '{"duration_s": 1, "robot": {"modules": [{}, {"ripple": {"phase_2x_deg": 400}}], "links": [{}, {}]}}\n' \
  >"$tmp/bad_ripple.json"
run bad_ripple_value "$armfault" trace "$tmp/bad_ripple.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/bad_ripple.json: /robot/modules/1/ripple/phase_2x_deg: 400 is outside [-360, 360]"
printf '{"duration_s": 1, "robot": {"modules": [{"ripple": {"cogging_Nm": 1e999}}], "links": [{}]}}\n' \
  >"$tmp/huge_ripple.json"
run huge_ripple_value "$armfault" trace "$tmp/huge_ripple.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/huge_ripple.json: /robot/modules/0/ripple/cogging_Nm: the number 1e999 is beyond the range of a double"
printf '{"duration_s": 1, "robot": {"modules": [{"ripple": true}], "links": [{}]}}\n' >"$tmp/ripple_type.json"
run ripple_not_object "$armfault" trace "$tmp/ripple_type.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/ripple_type.json: /robot/modules/0/ripple: expected an object"

printf 'robot = mrr-config1\nduration = 1\n' >"$tmp/not_json.json"
run not_json "$armfault" trace "$tmp/not_json.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/not_json.json: (document root): not valid JSON: "

: >"$tmp/empty.json"
run empty_file "$armfault" trace "$tmp/empty.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/empty.json: (document root): the input is empty"

printf '{"robot": "mrr-config1", "joints": {"3": {"type": "sine_pa' >"$tmp/truncated.json"
run truncated_file "$armfault" trace "$tmp/truncated.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/truncated.json: (document root): not valid JSON: "

printf '[1, 2, 3]\n' >"$tmp/array.json"
run not_an_object "$armfault" trace "$tmp/array.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/array.json: (document root): expected a JSON object describing a run"

run missing_file "$armfault" trace "$tmp/does_not_exist.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/does_not_exist.json: (document root): cannot open the file for reading"

run joint_out_of_range "$armfault" trace --joint '3={"type":"sine_pair","amplitude_deg":200,"omega_rad_s":1}' \
  -q -o "$tmp/x.csv"
expect_input_error "/joints/3: the trajectory spans [-259.808, 259.808] deg, beyond joint 3's range [-120, 120] deg"

run unknown_joint "$armfault" trace --joint '7={"type":"hold"}' -q -o "$tmp/x.csv"
expect_input_error '/joints/7: "7" is not a joint of robot mrr-config1 (joints 1..3)'

run joint_not_json "$armfault" trace --joint '3={"type":' -q -o "$tmp/x.csv"
expect_input_error "armfault: error: --joint 3: not valid JSON: "

run joint_without_equals "$armfault" trace --joint 3 -q -o "$tmp/x.csv"
expect_input_error "armfault: error: --joint: expected J=<trajectory JSON>, got \"3\""

run duration_zero "$armfault" trace --duration 0 -q -o "$tmp/x.csv"
expect_input_error "/duration_s: 0 is outside [0.002, 3600]"

run unwritable_output "$armfault" trace --duration 0.01 -q -o "$tmp/no/such/dir/t.csv"
expect_input_error "$tmp/no/such/dir/t.csv.tmp: (document root): cannot open for writing: No such file or directory"

# Every subcommand `--help` lists has its row in the README's command table.
current=readme_lists_every_command
for name in $("$armfault" --help | sed -n '/^Subcommands:/,$p' | awk 'NR > 1 && !NF { exit } NR > 1 { print $1 }'); do
  if grep -qF "| \`armfault $name" "$src/README.md"; then pass; else fail "README.md has no row for \`armfault $name\`"; fi
done

# ------------------------------------------------------------------ trace output

run trace "$armfault" trace --duration 0.5 -o "$tmp/t.csv"
expect_status 0
expect_stdout_contains "run: robot mrr-config1"
expect_stdout_contains "energy balance"
if [[ -f "$tmp/t.csv" ]]; then
  pass
  header=$(head -n 1 "$tmp/t.csv")
  if [[ $header == t_s,q_ref_rad_j1,q_rad_j1,* ]]; then pass; else fail "header starts '${header:0:40}'"; fi
  # channels.json beside it: one entry per column, in order, with unit and source.
  if python3 -c 'import json,sys; c=json.load(open(sys.argv[1]))["channels"]; h=open(sys.argv[2]).readline().strip().split(","); sys.exit(not ([x["name"] for x in c]==h and c[1]["unit"]=="rad" and c[2]["source"]=="truth"))' \
      "$tmp/t.channels.json" "$tmp/t.csv"; then pass; else fail "t.channels.json does not describe t.csv's columns"; fi
  rows=$(($(wc -l <"$tmp/t.csv") - 1))
  if [[ $rows -eq 251 ]]; then pass; else fail "$rows data rows, expected 251 (500 Hz, t = 0 .. 0.5)"; fi
  first_t=$(sed -n 2p "$tmp/t.csv" | cut -d, -f1)
  last_t=$(tail -n 1 "$tmp/t.csv" | cut -d, -f1)
  second_t=$(sed -n 3p "$tmp/t.csv" | cut -d, -f1)
  if [[ $first_t == 0 && $second_t == 0.002 && $last_t == 0.5 ]]; then pass; else
    fail "times $first_t, $second_t ... $last_t, expected 0, 0.002 ... 0.5"
  fi
  # Every row has as many fields as the header; no NaN or inf anywhere.
  if awk -F, 'NR == 1 { n = NF } NF != n { bad = 1 } END { exit bad }' "$tmp/t.csv"; then pass; else
    fail "rows with a field count different from the header"
  fi
  if grep -qiE 'nan|inf' <(tail -n +2 "$tmp/t.csv"); then fail "non-finite values in the trace"; else pass; fi
else
  fail "no trace file written"
fi

current=trace_in_cwd
(cd "$tmp/elsewhere" && "$armfault" trace --duration 0.01 -q >/dev/null 2>&1)
if [[ -f "$tmp/elsewhere/trace.csv" ]]; then pass; else fail "default output trace.csv not written to the working directory"; fi

run trace_quiet "$armfault" trace --duration 0.5 -q -o "$tmp/t2.csv"
expect_status 0
if [[ ! -s "$tmp/stdout" ]]; then pass; else fail "-q still printed: $(head -c 200 "$tmp/stdout")"; fi

current=trace_deterministic
if cmp -s "$tmp/t.csv" "$tmp/t2.csv"; then pass; else fail "two identical traces differ"; fi

run trace_other_seed "$armfault" trace --duration 0.5 --seed 2 -q -o "$tmp/t3.csv"
expect_status 0
if cmp -s "$tmp/t.csv" "$tmp/t3.csv"; then fail "--seed 2 gives the same trace as seed 1"; else pass; fi

# A run file: its robot and trajectory apply, and a csv path is resolved next to the file.
printf 'time_s,angle_deg\n0,0\n0.2,5\n0.4,0\n' >"$tmp/ramp.csv"
printf '{"robot": "pendulum", "duration_s": 0.1, "seed": 3, "joints": {"1": {"type": "csv", "path": "ramp.csv"}}}\n' \
  >"$tmp/pendulum.json"
current=run_file
(cd "$tmp/elsewhere" && "$armfault" trace ../pendulum.json -q -o "$tmp/p.csv" >"$tmp/stdout" 2>"$tmp/stderr")
status=$?
expect_status 0
if [[ -f "$tmp/p.csv" ]]; then
  header=$(head -n 1 "$tmp/p.csv")
  if [[ $header == t_s,q_ref_rad_j1,* && $header != *q_ref_rad_j2* ]]; then pass; else fail "pendulum header '${header:0:60}'"; fi
  rows=$(($(wc -l <"$tmp/p.csv") - 1))
  if [[ $rows -eq 51 ]]; then pass; else fail "$rows data rows, expected 51"; fi
else
  fail "no trace file written"
fi

# Command-line values override the run file.
run run_file_override "$armfault" trace "$tmp/pendulum.json" --duration 0.05 -q -o "$tmp/p2.csv"
expect_status 0
if [[ -f "$tmp/p2.csv" ]]; then
  rows=$(($(wc -l <"$tmp/p2.csv") - 1))
  if [[ $rows -eq 26 ]]; then pass; else fail "$rows data rows, expected 26"; fi
else
  fail "no trace file written"
fi

# ------------------------------------------------------------------ overrides
# A run file whose "joints" is not an object, combined with --joint.
  printf '{"joints": []}\n' >"$tmp/joints_array.json"
  run joints_array_plus_joint_flag "$armfault" trace "$tmp/joints_array.json" --joint '3={"type":"hold"}' -q -o "$tmp/x.csv"
  expect_input_error "$tmp/joints_array.json: /joints: "

  # Negative --duration / --seed are errors, not "option not given".
  run negative_duration "$armfault" trace --duration -1 -q -o "$tmp/x.csv"
  expect_input_error "/duration_s: -1 is outside [0.002, 3600]"
  run negative_seed "$armfault" trace --duration 0.01 --seed -5 -q -o "$tmp/x.csv"
  expect_input_error "/seed: "

# ------------------------------------------------------------------ faults
run fault_bad_factor "$armfault" trace --duration 0.1 -q -o "$tmp/x.csv" --fault '{"family":"kt_degradation","joint":3,"kt_factor":1.4}'
expect_input_error "<command line>: /faults/0/kt_factor: kt_degradation: 1.4 is outside"
run fault_bad_joint "$armfault" trace --duration 0.1 -q -o "$tmp/x.csv" --fault '{"family":"brake_lock","joint":4,"drag_fraction":1}'
expect_input_error "/faults/0/joint: brake_lock: joint 4 does not exist"
run fault_bad_family "$armfault" trace --duration 0.1 -q -o "$tmp/x.csv" --fault '{"family":"gremlins","joint":3}'
expect_input_error '/faults/0/family: unknown fault family "gremlins"'
printf '{"duration_s": 0.1, "faults": [{"family": "torque_sensor_stuck", "joint": 3, "lead": "vcc"}]}\n' >"$tmp/fault_run.json"
run fault_in_file "$armfault" trace "$tmp/fault_run.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/fault_run.json: /faults/0/lead: torque_sensor_stuck: unknown lead \"vcc\""
run fault_ok "$armfault" trace --duration 1 -o "$tmp/x.csv" --fault '{"family":"kt_degradation","joint":3,"kt_factor":0.5,"onset_s":0.2}'
expect_status 0
if grep -q 'torque_per_ampere_Nm_per_A: .*took effect' "$tmp/stdout"; then pass; else fail "no took-effect line: $(cat "$tmp/stdout")"; fi

# ------------------------------------------------------------------ monitor
run monitor_alarm "$armfault" trace -o "$tmp/x.csv" --monitor-out "$tmp/m.json" --fault '{"family":"kt_degradation","joint":3,"kt_factor":0.7,"onset_s":2}'
expect_status 0
expect_stdout_contains "monitor: ALARM at "
expect_stdout_contains " at the alarm, "  # the first estimate and the last, apart
expect_stdout_contains ", 0.70"  # the last estimate: the fault's 0.7
expect_stdout_contains " at the end (confidence "
expect_stdout_contains ", joint 3, kt_degradation, kt_factor 0."
if grep -q '"isolated_family": "kt_degradation"' "$tmp/m.json" && grep -q '"windows": \[' "$tmp/m.json"; then pass; else fail "monitor JSON lacks the diagnosis or windows: $(head -c 300 "$tmp/m.json")"; fi
run monitor_quiet_healthy "$armfault" trace -o "$tmp/x.csv"
expect_stdout_contains "monitor: no alarm"
printf '{"duration_s": 0.1, "monitor": {"kt_factor": {"worn": 0.9, "defectve": 0.5}}}\n' >"$tmp/monitor_key.json"
run monitor_unknown_key "$armfault" trace "$tmp/monitor_key.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/monitor_key.json: /monitor/kt_factor/defectve: unknown key"
printf '{"debounce_s": -2}\n' >"$tmp/thresholds.json"
printf '{"duration_s": 0.1, "monitor": "thresholds.json"}\n' >"$tmp/monitor_file.json"
run monitor_file_bad_value "$armfault" trace "$tmp/monitor_file.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/thresholds.json: /debounce_s: -2 is outside"
# The estimators' constants are settings too, range-checked and checked against each other.
printf '{"duration_s": 0.1, "monitor": {"max_lubricant_slope_per_K": -0.01}}\n' >"$tmp/monitor_constant.json"
run monitor_constant_out_of_range "$armfault" trace "$tmp/monitor_constant.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/monitor_constant.json: /monitor/max_lubricant_slope_per_K: -0.01 is outside"
printf '{"duration_s": 0.1, "monitor": {"friction_envelope_blocks": 10}}\n' >"$tmp/monitor_blocks.json"
run monitor_constants_inconsistent "$armfault" trace "$tmp/monitor_blocks.json" -q -o "$tmp/x.csv"
expect_input_error "$tmp/monitor_blocks.json: /monitor/shown_friction_blocks: 20 is outside"

# ------------------------------------------------------------------ thesis
run thesis "$armfault" thesis -o "$tmp/thesis"
expect_status 0
expect_stdout_contains "trend: table 5-3 falls monotonically: yes"
# thesis.json is written with 2-space indentation: one key per line.
if grep -q '"kt_factor": 0.9,' "$tmp/thesis/thesis.json" && grep -q '"thesis_pct": 73.7,' "$tmp/thesis/thesis.json" &&
  grep -q '"table_5_3": \[' "$tmp/thesis/thesis.json" && grep -q '"spring_load": true,' "$tmp/thesis/thesis.json" &&
  [[ $(grep -c '"armfault_pct": [0-9]' "$tmp/thesis/thesis.json") -eq 10 ]]
then pass; else fail "thesis.json is not as documented"; fi
if grep -q '^| n = 0.9 | 73.70 |' "$tmp/thesis/thesis.md"; then pass; else fail "thesis.md lacks the table row"; fi

# ------------------------------------------------------------------ campaigns
run validate_ci "$armfault" validate "$src/campaigns/files/ci.json"
expect_status 0
expect_stdout_contains "valid campaign \"ci\": 52 runs"
printf '{"trajectories": [{"name": "a", "joints": {"3": {"type": "hold"}}}], "healthy": 1, "duration_s": 0.5}\n' >"$tmp/one_of_each.json"
run validate_plurals "$armfault" validate "$tmp/one_of_each.json"
expect_stdout_contains "valid campaign \"one_of_each\": 1 run (1 trajectory, 0 fault entries, 1 healthy per trajectory, 1 repetition)"
printf '{"trajectories": [{"name": "a", "joints": {"3": {"type": "hold"}}}], "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.9, 1.5]}]}\n' >"$tmp/bad_campaign.json"
run campaign_bad_value "$armfault" validate "$tmp/bad_campaign.json"
expect_input_error "$tmp/bad_campaign.json: /faults/0/kt_factor/1: kt_degradation: 1.5 is outside"
# JSON itself: a number beyond a double and a key given twice are errors naming the field (the
# number aborted before), in a campaign, a run directory's campaign.json and a --fault.
printf '{"duration_s": 1e999, "trajectories": [{"name": "a", "joints": {"3": {"type": "hold"}}}]}\n' >"$tmp/huge.json"
run campaign_huge_number "$armfault" validate "$tmp/huge.json"
expect_input_error "$tmp/huge.json: /duration_s: the number 1e999 is beyond the range of a double"
run campaign_huge_number_run "$armfault" run "$tmp/huge.json" -o "$tmp/huge_out" -q
expect_input_error "$tmp/huge.json: /duration_s: the number 1e999 is beyond the range of a double"
printf '{"trajectories": [{"name": "a", "name": "b", "joints": {}}]}\n' >"$tmp/twice.json"
run campaign_key_twice "$armfault" validate "$tmp/twice.json"
expect_input_error "$tmp/twice.json: /trajectories/0/name: the key \"name\" is given twice in one object"
run trace_fault_huge "$armfault" trace --fault '{"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": -1e400}'
expect_status 2
expect_stderr_contains "/onset_s: the number -1e400 is beyond the range of a double"
# Output files are never written through a symbolic link: the run is refused, the target intact.
mkdir -p "$tmp/linked"
printf 'precious\n' >"$tmp/precious.txt"
ln -s "$tmp/precious.txt" "$tmp/linked/results.jsonl"
run run_through_link "$armfault" run "$src/campaigns/files/ci.json" -o "$tmp/linked" -q
expect_input_error "$tmp/linked/results.jsonl: (document root): is a symbolic link: armfault does not write through links"
[[ "$(cat "$tmp/precious.txt")" == precious ]] && pass || fail "the link's target was written"
# Every error of a campaign, one line each, in the order found; then exit 2. `run` prints the
# same and writes nothing.
printf '%s\n' '{"trajectories": [{"name": "a", "joints": {"3": {"type": "hold", "angle_deg": 500}}}],' \
  ' "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.9, 1.5]}], "healthy": -1, "floors": {"detection_rte": 0.5}}' \
  >"$tmp/four_errors.json"
four_errors=("armfault: error: $tmp/four_errors.json: /trajectories/0/joints/3: the trajectory spans [500, 500] deg, beyond joint 3's range [-120, 120] deg"
  "armfault: error: $tmp/four_errors.json: /faults/0/kt_factor/1: kt_degradation: 1.5 is outside [0, 1]"
  "armfault: error: $tmp/four_errors.json: /healthy: -1 is outside [0, 1000000]"
  "armfault: error: $tmp/four_errors.json: /floors/detection_rte: unknown key \"detection_rte\"; did you mean \"detection_rate\"?")
for cmd in validate run; do
  if [[ $cmd == run ]]; then
    run campaign_all_errors_run "$armfault" run "$tmp/four_errors.json" -o "$tmp/not_written" -q
  else
    run campaign_all_errors_validate "$armfault" validate "$tmp/four_errors.json"
  fi
  expect_status 2
  if cmp -s "$tmp/stderr" <(printf '%s\n' "${four_errors[@]}"); then pass; else
    fail "stderr is not the four errors: $(cat "$tmp/stderr")"
  fi
  if [[ ! -s "$tmp/stdout" && ! -e "$tmp/not_written" ]]; then pass; else fail "invalid input printed or wrote something"; fi
done
# More than 20: the first 20, then how many more.
values=$(seq -s, 2 26)
printf '{"trajectories": [{"name": "a", "joints": {}}], "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [%s]}]}\n' \
  "$values" >"$tmp/many_errors.json"
run campaign_many_errors "$armfault" validate "$tmp/many_errors.json"
expect_status 2
if [[ $(wc -l <"$tmp/stderr") -eq 21 && $(sed -n 20p "$tmp/stderr") == *"/faults/0/kt_factor/19: kt_degradation: 21 is outside [0, 1]" &&
  $(tail -n 1 "$tmp/stderr") == "armfault: error: ... and 5 more errors" ]]; then pass; else
  fail "not 20 errors and '... and 5 more errors': $(head -c 400 "$tmp/stderr")"
fi
printf '{"trajectories": [{"name": "a", "joints": {"3": {"type": "hold"}}}], "healthy": 2, "duration_s": 0.5,\n "floors": {"false_alarm_rate": 0, "detection_rate": 0.5}}\n' >"$tmp/healthy_only.json"
run campaign_floor_missed "$armfault" run "$tmp/healthy_only.json" -o "$tmp/ho" -q
expect_status 1
expect_stdout_contains "MISSED  detection_rate: no faulty runs"
if [[ -s "$tmp/ho/summary.json" && -s "$tmp/ho/junit.xml" && $(wc -l <"$tmp/ho/results.jsonl") -eq 2 && $(wc -l <"$tmp/ho/results.csv") -eq 3 ]]; then pass; else fail "campaign outputs missing"; fi
run campaign_bad_shard "$armfault" run "$tmp/healthy_only.json" -o "$tmp/ho" -q --shard 3/3
expect_input_error "shard 3 of 3 does not exist"
run bench "$armfault" bench --repeats 1
expect_status 0
expect_stdout_contains "ratio: "
expect_stdout_contains "parallel efficiency: "
run bench_length "$armfault" bench --duration 0.2 --duration 0.4 --duration 0.6 --repeats 1
expect_status 0
expect_stdout_contains "ms_per_sim_s marginal_ms_per_s"
expect_stdout_contains "marginal ratio (last step / first step): "
run bench_length_too_long "$armfault" bench --duration 3601
if [[ $status -ne 0 ]]; then pass; else fail "a 3601-s bench run was accepted"; fi

# ------------------------------------------------------------------ diff (armfault diff)
# One real run of the CI campaign is A; the B directories are edited copies of it.
run diff_setup "$armfault" run "$src/campaigns/files/ci.json" -o "$tmp/diff_a" -q
expect_status 0
run diff_same "$armfault" diff "$tmp/diff_a" "$tmp/diff_a" -o "$tmp/diff.json" --markdown "$tmp/diff.md"
expect_status 0
expect_stdout_contains 'same campaign "ci"'
expect_stdout_contains ' 0 worse, '
if grep -q '"worse": false' "$tmp/diff.json" && grep -qF '| scope | metric | A | B |' "$tmp/diff.md"; then pass; else
  fail "diff.json or diff.md not as documented"
fi
# B: no kt_degradation run detected any more: detection significantly worse, exit 1.
mkdir "$tmp/diff_b" "$tmp/diff_c" "$tmp/diff_d"
cp "$tmp/diff_a/campaign.json" "$tmp/diff_b/"
sed '/"family":"kt_degradation"/s/"detected":true/"detected":false/' "$tmp/diff_a/results.jsonl" >"$tmp/diff_b/results.jsonl"
run diff_worse "$armfault" diff "$tmp/diff_a" "$tmp/diff_b"
expect_status 1
expect_stdout_contains "worse: overall detection: "
expect_stdout_contains "worse: family kt_degradation detection: 1.000 (8/8) -> 0.000 (0/8)"
run diff_tolerance "$armfault" diff "$tmp/diff_a" "$tmp/diff_b" --tolerance 1
expect_status 0
# A summary.json that does not match results.jsonl only warns.
cp "$tmp/diff_a/summary.json" "$tmp/diff_b/"
run diff_stale_summary "$armfault" diff "$tmp/diff_a" "$tmp/diff_b" --tolerance 1
expect_status 0
expect_stderr_contains "$tmp/diff_b/summary.json does not match"
# C: the brake_lock runs dropped and the campaign renamed: listed, warned, not an error.
grep -v '"family":"brake_lock"' "$tmp/diff_a/results.jsonl" >"$tmp/diff_c/results.jsonl"
sed 's/^    "name": "ci",$/    "name": "ci-copy",/' "$tmp/diff_a/campaign.json" >"$tmp/diff_c/campaign.json"
run diff_only_in_a "$armfault" diff "$tmp/diff_a" "$tmp/diff_c"
expect_status 0
expect_stdout_contains "only in A: brake_lock drag_fraction=1 joint=3"
expect_stderr_contains "armfault: warning: the campaigns differ in: name; comparisons are by group key"
# Bad input: status 2, naming the directory, or the file and the line.
run diff_missing_dir "$armfault" diff "$tmp/diff_a" "$tmp/no_such_dir"
expect_input_error "$tmp/no_such_dir: (document root): no such directory"
run diff_missing_results "$armfault" diff "$tmp/diff_a" "$tmp/diff_d"
expect_input_error "$tmp/diff_d/results.jsonl: (document root): no such file"
cp "$tmp/diff_a/results.jsonl" "$tmp/diff_d/results.jsonl"
printf '{"case": 52, "run_id": \n' >>"$tmp/diff_d/results.jsonl"
run diff_bad_line "$armfault" diff "$tmp/diff_a" "$tmp/diff_d"
expect_input_error "$tmp/diff_d/results.jsonl: line 53: "
run diff_bad_alpha "$armfault" diff "$tmp/diff_a" "$tmp/diff_a" --alpha 2
expect_input_error "--alpha: 2 is outside (0, 1]"

# The sequential decision's target rate: > 0, at most one per controller tick, only with it.
seq_campaign() {  # seq_campaign NAME MONITOR_JSON
  printf '{"name": "seq", "duration_s": 1, "trajectories": [{"name": "t", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 1}}}], "faults": [], "healthy": 1, "monitor": %s}\n' "$2" >"$tmp/$1.json"
}
seq_campaign seq_zero '{"decision": "sequential", "target_false_alarms_per_hour": 0}'
run seq_zero "$armfault" validate "$tmp/seq_zero.json"
expect_input_error "$tmp/seq_zero.json: /monitor/target_false_alarms_per_hour: 0 is not a false-alarm rate: alarms per hour must be > 0"
seq_campaign seq_negative '{"decision": "sequential", "target_false_alarms_per_hour": -1}'
run seq_negative "$armfault" validate "$tmp/seq_negative.json"
expect_input_error "$tmp/seq_negative.json: /monitor/target_false_alarms_per_hour: -1 is not a false-alarm rate"
seq_campaign seq_per_tick '{"decision": "sequential", "target_false_alarms_per_hour": 2e9}'
run seq_per_tick "$armfault" validate "$tmp/seq_per_tick.json"
expect_input_error "$tmp/seq_per_tick.json: /monitor/target_false_alarms_per_hour: 2000000000 alarms per hour is more than one per controller tick (1800000 per hour at 500 Hz)"
seq_campaign seq_alone '{"target_false_alarms_per_hour": 1}'
run seq_alone "$armfault" validate "$tmp/seq_alone.json"
expect_input_error "$tmp/seq_alone.json: /monitor/target_false_alarms_per_hour: target_false_alarms_per_hour sets the sequential decision: it needs \"decision\": \"sequential\""
seq_campaign seq_typo '{"decision": "sequental"}'
run seq_typo "$armfault" validate "$tmp/seq_typo.json"
expect_input_error "$tmp/seq_typo.json: /monitor/decision: unknown decision \"sequental\" (known: threshold, sequential); did you mean \"sequential\"?"

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
