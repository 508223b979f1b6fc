#!/usr/bin/env python3
"""Writes the fuzzers' seed corpus, tests/fuzz/corpus/<target>/, from the shipped files.

    tests/fuzz/make_corpus.py build/armfault

campaign: campaigns/files/*.json as they are. robot: the docs' example objects, the presets by
name, and mrr-config1 and pendulum written back in full (every key, as a run's campaign.json
writes them). monitor: {} and the power-efficiency settings in full (as campaign.json writes
them). run: the README's run file, one with faults and a monitor, one per trajectory type.
verdicts: the first lines of tests/app/golden/verdicts.jsonl and lines with every optional key.
The full robots and monitor come from a 0.5-s campaign run with the armfault binary given.
Small on purpose (the repository stays light); the fuzzer grows its own corpus in its build
directory. Rerun after a format change; commit what it writes.
"""
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

src = pathlib.Path(__file__).resolve().parents[2]
out = src / "tests" / "fuzz" / "corpus"


def resolved(armfault, robot):
    """The campaign.json "campaign" of a one-run campaign on `robot`: every key filled in."""
    with tempfile.TemporaryDirectory() as tmp:
        camp = pathlib.Path(tmp) / "c.json"
        joint = "3" if robot == "mrr-config1" else "1"
        camp.write_text(json.dumps({
            "name": "seed", "robot": robot, "duration_s": 0.2, "healthy": 1, "faults": [],
            "trajectories": [{"name": "t", "joints": {joint: {"type": "hold"}}}]}))
        subprocess.run([armfault, "run", str(camp), "-o", str(pathlib.Path(tmp) / "o"), "-q"], check=True,
                       stdout=subprocess.DEVNULL)
        return json.loads((pathlib.Path(tmp) / "o" / "campaign.json").read_text())["campaign"]


def write(target, name, text):
    d = out / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_text(text if text.endswith("\n") else text + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    armfault = sys.argv[1]
    shutil.rmtree(out, ignore_errors=True)

    for f in sorted((src / "campaigns" / "files").glob("*.json")):
        write("campaign", f.name, f.read_text())

    mrr, pendulum = resolved(armfault, "mrr-config1"), resolved(armfault, "pendulum")
    write("robot", "preset-mrr.json", json.dumps("mrr-config1"))
    write("robot", "preset-pendulum.json", json.dumps("pendulum"))
    write("robot", "docs-two-joint.json", json.dumps(
        {"name": "two-joint", "modules": [{"type": "MRR1"}, {"motor": {"kt_Nm_per_A": 0.17}}],
         "links": [{"mass_kg": 2, "direction": [0, 0, 1], "joint_axis": [0, 0, 1]}, {}], "payload_kg": 1}))
    # The optional ripple group (core/plant/parts/torque_ripple.h): one module with its defaults, one with some keys.
    write("robot", "ripple-two-joint.json", json.dumps(
        {"name": "ripple", "modules": [{"type": "MRR1", "ripple": {}},
                                       {"ripple": {"cogging_Nm": 0.02, "cogging_periods_per_rev": 36, "phase_2x_deg": 30}}],
         "links": [{"mass_kg": 2, "direction": [0, 0, 1], "joint_axis": [0, 0, 1]}, {}], "payload_kg": 1}))
    write("robot", "full-mrr-config1.json", json.dumps(mrr["robot"], indent=1))
    write("robot", "full-pendulum.json", json.dumps(pendulum["robot"], indent=1))

    write("monitor", "empty.json", "{}")
    write("monitor", "full.json", json.dumps(mrr["monitor"], indent=1))
    write("monitor", "typed.json", json.dumps({"type": "power_efficiency", "debounce_s": 0.5, "min_window_s": 0.2}))

    sine = {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}
    write("run", "readme.json", json.dumps({"robot": "mrr-config1", "duration_s": 10, "seed": 1, "joints": {"3": sine}}))
    write("run", "faults.json", json.dumps({
        "duration_s": 4, "joints": {"3": sine}, "monitor": {"debounce_s": 0.4},
        "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": 2, "profile": "abrupt"},
                   {"family": "friction_increase", "joint": 2, "friction_factor": 2,
                    "onset": {"when": "joint_velocity_above", "joint": 3, "rad_s": 0.5}}]}))
    write("run", "trajectories.json", json.dumps({
        "robot": "mrr-config1", "duration_s": 3, "joints": {
            "1": {"type": "hold", "angle_deg": 10},
            "2": {"type": "cosine_ramp", "amplitude_deg": 20, "period_s": 2, "offset_deg": 5},
            "3": {"type": "min_jerk", "waypoints": [[0, 0], [1, 20], [2.5, -10]]}}}))
    write("run", "pendulum.json", json.dumps({"robot": pendulum["robot"], "duration_s": 1, "seed": 7}))

    golden = (src / "tests" / "app" / "golden" / "verdicts.jsonl").read_text().splitlines()
    write("verdicts", "golden-head.jsonl", "\n".join(golden[:4]))
    write("verdicts", "optional-keys.jsonl", "\n".join(json.dumps(v) for v in [
        {"run_id": "a", "t_s": 0.5, "joint": 1, "family": None, "alarm": False, "magnitude": None},
        {"run_id": "a", "t_s": 2.0, "joint": 2, "family": "brake_lock", "alarm": True, "magnitude": 0.3,
         "state": "defective", "magnitude_name": "drag_fraction", "confidence": 0.8},
        {"run_id": "b", "t_s": 1.0, "joint": 3, "family": "unknown", "alarm": True, "magnitude": 0, "state": "worn"},
    ]) + "\n\n")


if __name__ == "__main__":
    main()
