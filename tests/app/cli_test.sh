#!/usr/bin/env bash
# End-to-end checks of the armfault command line: exit statuses, error messages on stderr and
# the trace CSV. Usage: cli_test.sh path/to/armfault
# Prints one line per failed check and a final "N passed, M failed"; exits non-zero on failure.
set -u

if [[ $# -ne 1 || ! -x "$1" ]]; then
  echo "usage: $0 path/to/armfault" >&2
  exit 2
fi
armfault=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
src=$(cd "$(dirname "$0")/../.." && pwd)  # the source tree (shipped campaigns)

tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_cli_test.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/work" "$tmp/elsewhere"
cd "$tmp/work" || exit 2  # stray default outputs (trace.csv) land in the temp dir

passed=0
failed=0
status=0

pass() { passed=$((passed + 1)); }
fail() {
  failed=$((failed + 1))
  echo "FAIL: $current: $*"
}

# run NAME CMD...: runs CMD, keeping its exit status in $status and its output in files.
run() {
  current=$1
  shift
  "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  status=$?
}

expect_status() {
  if [[ $status -eq $1 ]]; then pass; else fail "exit status $status, expected $1; stderr: $(head -c 400 "$tmp/stderr")"; fi
}

expect_stderr_contains() {
  if grep -qF -- "$1" "$tmp/stderr"; then pass; else fail "stderr lacks '$1'; stderr: $(head -c 400 "$tmp/stderr")"; fi
}

expect_stdout_contains() {
  if grep -qF -- "$1" "$tmp/stdout"; then pass; else fail "stdout lacks '$1'; stdout: $(head -c 400 "$tmp/stdout")"; fi
}

# An invalid-input error: status 2 and exactly one line "armfault: error: <expected...>".
expect_input_error() {
  expect_status 2
  local lines first
  lines=$(wc -l <"$tmp/stderr")
  first=$(head -n 1 "$tmp/stderr")
  if [[ $lines -eq 1 && $first == "armfault: error: "* ]]; then pass; else fail "stderr is not one 'armfault: error: ' line: $(head -c 400 "$tmp/stderr")"; fi
  local needle
  for needle in "$@"; do expect_stderr_contains "$needle"; done
}

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
  'armfault: error: <command line>: /robot: unknown robot preset "nope" (known: mrr-config1, pendulum)'

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
expect_input_error "armfault: error: --joint 3: (document root): not valid JSON: "

run joint_without_equals "$armfault" trace --joint 3 -q -o "$tmp/x.csv"
expect_input_error "armfault: error: --joint: (document root): expected J=<trajectory JSON>, got \"3\""

run duration_zero "$armfault" trace --duration 0 -q -o "$tmp/x.csv"
expect_input_error "/duration_s: 0 is outside [0.002, 3600]"

run unwritable_output "$armfault" trace --duration 0.01 -q -o "$tmp/no/such/dir/t.csv"
expect_input_error "$tmp/no/such/dir/t.csv: (document root): cannot open the trace file for writing"

# ------------------------------------------------------------------ trace output

run trace "$armfault" trace --duration 0.5 -o "$tmp/t.csv"
expect_status 0
expect_stdout_contains "run: robot mrr-config1"
expect_stdout_contains "energy balance"
if [[ -f "$tmp/t.csv" ]]; then
  pass
  header=$(head -n 1 "$tmp/t.csv")
  if [[ $header == t,q_ref_1,* ]]; then pass; else fail "header starts '${header:0:40}'"; fi
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
  if [[ $header == t,q_ref_1,* && $header != *q_ref_2* ]]; then pass; else fail "pendulum header '${header:0:60}'"; fi
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
expect_stdout_contains ", joint 3, kt_degradation, kt_factor 0.7"
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
printf '{"trajectories": [{"name": "a", "joints": {"3": {"type": "hold"}}}], "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.9, 1.5]}]}\n' >"$tmp/bad_campaign.json"
run campaign_bad_value "$armfault" validate "$tmp/bad_campaign.json"
expect_input_error "$tmp/bad_campaign.json: /faults/0/kt_factor/1: kt_degradation: 1.5 is outside"
printf '{"trajectories": [{"name": "a", "joints": {"3": {"type": "hold"}}}], "healthy": 2, "duration_s": 0.5,\n "floors": {"false_alarm_rate": 0, "detection_rate": 0.5}}\n' >"$tmp/healthy_only.json"
run campaign_floor_missed "$armfault" run "$tmp/healthy_only.json" -o "$tmp/ho" -q
expect_status 1
expect_stdout_contains "MISSED  detection_rate: no faulty runs"
if [[ -s "$tmp/ho/summary.json" && -s "$tmp/ho/junit.xml" && $(wc -l <"$tmp/ho/results.jsonl") -eq 2 ]]; then pass; else fail "campaign outputs missing"; fi
run campaign_bad_shard "$armfault" run "$tmp/healthy_only.json" -o "$tmp/ho" -q --shard 3/3
expect_input_error "shard 3 of 3 does not exist"
run bench "$armfault" bench --repeats 1
expect_status 0
expect_stdout_contains "ratio: "
expect_stdout_contains "parallel efficiency: "

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
