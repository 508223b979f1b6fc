#!/usr/bin/env bash
# The example C plugin through the command line (docs/monitor-api.md, "C plugin"):
# tests/core/monitors/data/plugin_campaign.json names "libcurrent_residual.so" beside itself;
# this script puts the built example there, in a temp directory, and checks that
#   - `armfault run` meets the campaign's floors (exit 0), with 1 and with 2 threads giving the
#     same results.jsonl, and campaign.json records the library's absolute path;
#   - a library that is missing, or whose create refuses its settings, is exit 2 naming the
#     campaign file, /monitor/library and the library;
#   - a plugin whose step returns an error fails those runs (exit 3) with the reason, and the
#     campaign goes on; `report` and `trace` of such a run say so (trace: exit 3), never crash;
#   - statistics for tune: `tune` of the example's default mode (no statistics) is exit 2 saying
#     so; in threshold mode it sweeps the two statistics, writes the tuned thresholds into the
#     plugin's settings, and that tuned monitor, run again, scores exactly what tune predicted.
# Usage: plugin_campaign_test.sh ARMFAULT EXAMPLE_PLUGIN TEST_PLUGIN. Prints "N passed, M failed".
set -euo pipefail

if [[ $# -ne 3 ]]; then
  echo "usage: $0 ARMFAULT EXAMPLE_PLUGIN TEST_PLUGIN" >&2
  exit 2
fi
armfault=$1
example=$2
test_plugin=$3
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_plugin_campaign.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

passed=0
failed=0
check() {  # check NAME CONDITION-COMMAND...
  local name=$1
  shift
  if "$@" >"$tmp/out" 2>&1; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $name: $(head -c 800 "$tmp/out")"; fi
}

cp "$here/data/plugin_campaign.json" "$tmp/plugin_campaign.json"
cp "$example" "$tmp/libcurrent_residual.so"

runs_with() {  # runs_with THREADS: the campaign meets its floors, no run failed
  "$armfault" run "$tmp/plugin_campaign.json" -o "$tmp/out$1" -j "$1" -q
}
check run_one_thread runs_with 1
check run_two_threads runs_with 2
check same_results_any_thread_count cmp "$tmp/out1/results.jsonl" "$tmp/out2/results.jsonl"
recorded() {
  grep -qF "\"library\": \"$tmp/libcurrent_residual.so\"" "$tmp/out1/campaign.json"
}
check campaign_json_records_the_absolute_library recorded

# A campaign with another "monitor" value, beside the first.
with_monitor() {  # with_monitor NAME MONITOR_JSON
  sed "s|\"monitor\": {[^}]*}}|\"monitor\": $2|" "$tmp/plugin_campaign.json" >"$tmp/$1.json"
}
exit_2_naming() {  # exit_2_naming NAME TEXT...: `run` exits 2 and its error names each TEXT
  local name=$1 status=0
  shift
  "$armfault" run "$tmp/$name.json" -o "$tmp/out_$name" -q 2>"$tmp/err_$name" || status=$?
  [[ $status -eq 2 ]] || { echo "exit status $status, expected 2: $(cat "$tmp/err_$name")"; return 1; }
  for text in "$@"; do
    grep -qF -- "$text" "$tmp/err_$name" || { echo "the error does not name $text: $(cat "$tmp/err_$name")"; return 1; }
  done
}
with_monitor missing '{"type": "plugin", "library": "libnowhere.so"}'
check missing_library exit_2_naming missing "$tmp/missing.json: /monitor/library:" \
  "plugin library \"$tmp/libnowhere.so\" (resolved from \"libnowhere.so\") does not exist"
with_monitor refused "{\"type\": \"plugin\", \"library\": \"$test_plugin\", \"settings\": {\"mode\": \"create_error\"}}"
check create_refuses exit_2_naming refused "$tmp/refused.json: /monitor/library:" "$test_plugin" \
  "settings rejected: mode create_error"
with_monitor bad_setting '{"type": "plugin", "library": "libcurrent_residual.so", "settings": {"kt_wron": 0.8}}'
check bad_example_setting exit_2_naming bad_setting "/monitor/library:" "unknown setting \"kt_wron\""

step_error() {
  local status=0
  "$armfault" run "$tmp/step_error.json" -o "$tmp/out_step_error" -q 2>"$tmp/err_step_error" || status=$?
  [[ $status -eq 3 ]] || { echo "exit status $status, expected 3: $(cat "$tmp/err_step_error")"; return 1; }
  # Every run where joint 3 moves (all of them here) failed with the plugin's message, and all ran.
  [[ $(wc -l <"$tmp/out_step_error/results.jsonl") -eq 28 ]] &&
    [[ $(grep -c "monitor plugin failed: $test_plugin: step returned error: sensor model diverged at t = 1 s" \
          "$tmp/out_step_error/results.jsonl") -eq 28 ]]
}
with_monitor step_error "{\"type\": \"plugin\", \"library\": \"$test_plugin\", \"settings\": {\"mode\": \"step_error\"}}"
check step_error_fails_runs_campaign_goes_on step_error
# The commands that simulate one run again (report, trace) say so too, and do not crash.
report_after_step_error() {  # the page's run re-simulated shows the reason
  "$armfault" report "$tmp/out_step_error" &&
    grep -qF "$test_plugin: step returned error: sensor model diverged" "$tmp/out_step_error/report.html"
}
check report_after_step_error report_after_step_error
trace_step_error() {
  local status=0
  printf '%s\n' '{"duration_s": 2, "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}},' \
    " \"monitor\": {\"type\": \"plugin\", \"library\": \"$test_plugin\", \"settings\": {\"mode\": \"step_error\"}}}" \
    >"$tmp/run.json"
  "$armfault" trace "$tmp/run.json" -o "$tmp/trace.csv" >/dev/null 2>"$tmp/err_trace" || status=$?
  [[ $status -eq 3 ]] || { echo "exit status $status, expected 3: $(cat "$tmp/err_trace")"; return 1; }
  grep -qF "armfault: error: monitor failed: $test_plugin: step returned error: sensor model diverged" "$tmp/err_trace"
}
check trace_step_error trace_step_error

tune_without_statistics() {
  local status=0
  "$armfault" tune "$tmp/out1" >/dev/null 2>"$tmp/err_tune" || status=$?
  [[ $status -eq 2 ]] || { echo "exit status $status, expected 2"; return 1; }
  grep -qF '/campaign/monitor/type: monitor type "plugin" publishes no statistics tune can re-score' "$tmp/err_tune"
}
check tune_without_statistics tune_without_statistics
with_monitor thresholds '{"type": "plugin", "library": "libcurrent_residual.so", "settings": {"threshold_alarm": 1}}'
tuned_scores_as_predicted() {
  local status=0
  # As run, this mode names 13 of 16 faults right: below the isolation floor (exit 1).
  "$armfault" run "$tmp/thresholds.json" -o "$tmp/out_thresholds" -q >/dev/null || status=$?
  [[ $status -eq 1 ]] || { echo "run: exit status $status, expected 1 (isolation floor missed)"; return 1; }
  "$armfault" tune "$tmp/out_thresholds" >/dev/null
  grep -qF '"kt_deficit_threshold"' "$tmp/out_thresholds/tuned-monitor.json"
  sed "s|\"monitor\": {[^}]*}}|\"monitor\": \"$tmp/out_thresholds/tuned-monitor.json\"|" "$tmp/plugin_campaign.json" >"$tmp/tuned.json"
  "$armfault" run "$tmp/tuned.json" -o "$tmp/out_tuned" -q >/dev/null
  /usr/bin/python3 - "$tmp/out_thresholds/tuning.json" "$tmp/out_tuned/summary.json" <<'PY'
import json, sys
op = json.load(open(sys.argv[1]))["operating_point"]
overall = json.load(open(sys.argv[2]))["overall"]
predicted = (op["detection_rate"]["count"], op["false_alarm_rate"]["count"], op["isolation_accuracy"]["count"],
             op["latency_median_s"])
measured = (overall["detection"]["successes"], overall["false_alarm"]["successes"], overall["isolation"]["successes"],
            overall["latency"]["median_s"])
print("tune predicted", predicted, "the tuned run scored", measured)
sys.exit(0 if predicted == measured else 1)
PY
}
check tuned_scores_as_predicted tuned_scores_as_predicted

# trace --statistics of a plugin's run: its two statistics at every tick and joint beside their
# thresholds; on the first detected K_T run the faulted joint's kt_deficit passes its threshold
# first at the run's detection, never before the onset (reports/statistics_csv.h).
plugin_statistics() {
  local run
  run=$(/usr/bin/python3 -c 'import json,sys
rs=[json.loads(l) for l in open(sys.argv[1])]
print(next(r["case"] for r in rs if r["family"]=="kt_degradation" and r["detected"] and not r["alarm_before_onset"]
           and r["isolated_family"]=="kt_degradation" and r["isolated_joint"]==r["joint"]))' \
    "$tmp/out_thresholds/results.jsonl")
  "$armfault" trace "$tmp/out_thresholds/campaign.json" --run "$run" -o "$tmp/stats_trace.csv" \
    --statistics "$tmp/stats.csv" >"$tmp/stats_out"
  grep -qF "statistics: kt_deficit, friction_excess -> $tmp/stats.csv" "$tmp/stats_out" || { cat "$tmp/stats_out"; return 1; }
  /usr/bin/python3 - "$tmp/stats.csv" "$tmp/out_thresholds/results.jsonl" "$run" <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
record = [json.loads(l) for l in open(sys.argv[2])][int(sys.argv[3])]
assert list(rows[0]) == ["t_s", "joint", "statistic", "family", "value", "threshold", "above"], list(rows[0])
assert {r["statistic"] for r in rows} == {"kt_deficit", "friction_excess"}
kt = [r for r in rows if r["statistic"] == "kt_deficit" and int(r["joint"]) == record["joint"]]
above = [float(r["t_s"]) for r in kt if r["above"] == "1"]
assert above and min(above) == record["detection_time_s"], (above[:3], record["detection_time_s"])
assert min(above) >= record["onset_s"]
print("kt_deficit of joint", record["joint"], "passes first at", min(above), "= the detection")
PY
}
check plugin_trace_statistics plugin_statistics

# `validate` runs no code of the campaign's unless asked: a library whose constructor leaves a
# mark is not loaded (the mark stays absent, the output says why); --load-plugins loads it.
validate_loads_no_code() {
  printf '#include <stdio.h>\n__attribute__((constructor)) static void mark(void) { FILE* f = fopen(MARK, "w"); if (f) fclose(f); }\n' >"$tmp/mark.c"
  cc -shared -fPIC -DMARK="\"$tmp/ran\"" -o "$tmp/libmark.so" "$tmp/mark.c" || return 1
  with_monitor marked '{"type": "plugin", "library": "libmark.so"}'
  "$armfault" validate "$tmp/marked.json" >"$tmp/validate_out" || return 1
  [[ ! -e "$tmp/ran" ]] || { echo "validate ran the library's constructor"; return 1; }
  grep -qF 'monitor "plugin" not loaded: loading it runs its code with your rights; --load-plugins loads it' "$tmp/validate_out" ||
    { cat "$tmp/validate_out"; return 1; }
  local status=0
  "$armfault" validate --load-plugins "$tmp/marked.json" 2>"$tmp/validate_err" || status=$?
  [[ -e "$tmp/ran" ]] || { echo "--load-plugins did not load the library"; return 1; }
  # It exports no monitor functions: with the library loaded, that is the error.
  [[ $status -eq 2 ]] && grep -qF "does not export armfault_monitor_abi_version" "$tmp/validate_err" ||
    { echo "status $status: $(cat "$tmp/validate_err")"; return 1; }
}
check validate_loads_no_code validate_loads_no_code

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
