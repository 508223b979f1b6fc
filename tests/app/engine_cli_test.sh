#!/usr/bin/env bash
# The engine key on the command line: a campaign run in the articulated engine, its records
# naming it; bad input (an unknown engine, a robot the articulated engine cannot take) exits 2
# naming the file, the JSON pointer and the value; `bench --engine` with the three engines' lines.
# Usage: engine_cli_test.sh path/to/armfault
# Prints one line per failed check and a final "N passed, M failed"; exits non-zero on failure.
source "$(dirname "$0")/cli_common.sh"

hold='"trajectories": [{"name": "a", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 2}}}], "healthy": 2, "duration_s": 0.5'

# ------------------------------------------------------------------ runs and records
printf '{"engine": "articulated", %s}\n' "$hold" >"$tmp/articulated.json"
run articulated_run "$armfault" run "$tmp/articulated.json" -o "$tmp/art_out" -q
expect_status 0
if [[ $(grep -c '"engine":"articulated"' "$tmp/art_out/results.jsonl") -eq 2 ]]; then pass; else fail "the records do not name the articulated engine: $(head -c 300 "$tmp/art_out/results.jsonl")"; fi
printf '{%s}\n' "$hold" >"$tmp/ode.json"
run ode_run "$armfault" run "$tmp/ode.json" -o "$tmp/ode_out" -q
expect_status 0
if [[ $(grep -c '"engine":"ode"' "$tmp/ode_out/results.jsonl") -eq 2 ]]; then pass; else fail "the records do not name ODE"; fi
# The robot's own key, and the campaign's overriding it.
printf '{"robot": {"urdf": "%s/campaigns/files/robots/ur-class.urdf", "drives": {"shoulder_pan": "industrial-large", "shoulder_lift": "industrial-large", "elbow": "industrial-large", "wrist_1": "industrial-small", "wrist_2": "industrial-small", "wrist_3": "industrial-small"}, "engine": "articulated"}, %s}\n' "$src" "$hold" >"$tmp/robot_key.json"
run robot_key "$armfault" validate "$tmp/robot_key.json"
expect_status 0

# ------------------------------------------------------------------ bad input
printf '{"engine": "articulatd", %s}\n' "$hold" >"$tmp/typo.json"
run unknown_engine "$armfault" validate "$tmp/typo.json"
expect_input_error "$tmp/typo.json: /engine: unknown engine \"articulatd\" (known: ode, articulated); did you mean \"articulated\"?"
run unknown_engine_run "$armfault" run "$tmp/typo.json" -o "$tmp/typo_out" -q
expect_input_error "$tmp/typo.json: /engine: unknown engine \"articulatd\""
printf '{"robot": {"name": "r", "modules": [{"type": "MRR2"}], "links": [{}], "engine": "mujoco"}, %s}\n' "$hold" >"$tmp/robot_typo.json"
run unknown_robot_engine "$armfault" validate "$tmp/robot_typo.json"
expect_input_error "$tmp/robot_typo.json: /robot/engine: unknown engine \"mujoco\" (known: ode, articulated)"
printf '{"engine": 1, %s}\n' "$hold" >"$tmp/number.json"
run engine_not_a_name "$armfault" validate "$tmp/number.json"
expect_input_error "$tmp/number.json: /engine: expected \"ode\" or \"articulated\", got 1"
# Eight joints: ODE takes them, the articulated engine does not.
modules=$(printf '{"type": "MRR2"},%.0s' 1 2 3 4 5 6 7 8)
links=$(printf '{},%.0s' 1 2 3 4 5 6 7 8)
eight="{\"name\": \"eight\", \"modules\": [${modules%,}], \"links\": [${links%,}]}"
printf '{"robot": %s, "trajectories": [{"name": "a", "joints": {"8": {"type": "hold"}}}], "healthy": 1, "duration_s": 0.5}\n' "$eight" >"$tmp/eight_ode.json"
run eight_joints_ode "$armfault" validate "$tmp/eight_ode.json"
expect_status 0
printf '{"engine": "articulated", "robot": %s, "trajectories": [{"name": "a", "joints": {"8": {"type": "hold"}}}], "healthy": 1, "duration_s": 0.5}\n' "$eight" >"$tmp/eight.json"
run eight_joints "$armfault" validate "$tmp/eight.json"
expect_input_error "$tmp/eight.json: /engine: the articulated engine takes serial chains of 1 to 7 revolute joints; this robot has 8 joints"
run eight_joints_bench "$armfault" bench --robot "$tmp/eight_ode.json" --engine articulated --repeats 1
expect_status 2
expect_stderr_contains "--engine: the articulated engine takes serial chains of 1 to 7 revolute joints; this robot has 8 joints"
run bench_unknown_engine "$armfault" bench --engine bullet --repeats 1
expect_status 2
expect_stderr_contains "--engine: unknown engine \"bullet\""

# ------------------------------------------------------------------ bench
run bench_articulated "$armfault" bench --engine articulated --repeats 1
expect_status 0
expect_stdout_contains "engine articulated"
expect_stdout_contains "ratio: "
expect_stdout_contains "us per physics step: full run (articulated)"
# The three engines' bare stepping: ODE, the joint-space engine and MuJoCo (optional: CMake sets
# ARMFAULT_MUJOCO=1 when it built MuJoCo in, and the line says the model differs).
expect_stdout_contains "; bare ODE "
expect_stdout_contains "; bare articulated engine with its friction rows "
if [[ ${ARMFAULT_MUJOCO:-0} == 1 ]]; then
  expect_stdout_contains "us per physics step: bare MuJoCo 2."
  expect_stdout_contains "(a different model: each rotor an armature γ²·I_m on its own joint, without the geared rotor's I_m·γ coupling)"
else
  expect_stdout_contains "us per physics step: bare MuJoCo: not built in (libmujoco-dev was not found"
fi

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
