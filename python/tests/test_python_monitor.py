"""Monitors written in Python, scored by the same RunCase as the built-in one: the example
detects a strong fault and not a healthy run; a monitor that raises or breaks the contract fails
its run with the reason while the other runs go on; records do not depend on the threads."""
import json
import math
import re

import pytest

import armfault
from torque_ratio_monitor import TorqueRatioMonitor


def by_run(records):
    return {r["run_id"]: r for r in records}


def test_example_monitor_detects_a_strong_fault_and_not_a_healthy_run(small):
    records = by_run(armfault.run_campaign(small, monitor=TorqueRatioMonitor, threads=2, as_frame=False))
    assert len(records) == 4 and all(r["status"] == "ok" for r in records.values()), records
    faulty = records["exp1/kt_degradation#0/-/j3/r0"]
    assert faulty["detected"] and not faulty["alarm_before_onset"]
    assert faulty["isolated_family"] == "kt_degradation" and faulty["isolated_joint"] == 3
    assert 0 < faulty["latency_s"] < 2
    assert faulty["magnitude_name"] == "kt_factor" and 0.4 < faulty["magnitude_estimate"] < 0.7
    assert faulty.get("decision") is None  # statistics go to decisions.jsonl, not the records
    healthy = records["exp1/healthy/0"]
    assert not healthy["detected"] and healthy["miss_reason"] is None


class RaisesWhileJoint3Moves(armfault.Monitor):
    def step(self, t_s, signals):
        if t_s > 0.5 and signals.qd_ref_rad_s[2] != 0:
            raise RuntimeError("torque sensor lost")


def test_an_exception_fails_its_run_and_the_campaign_goes_on(small):
    with pytest.warns(armfault.RunsFailedWarning, match="2 of 4 runs failed; first failed run exp1/"):
        records = by_run(armfault.run_campaign(small, monitor=RaisesWhileJoint3Moves, as_frame=False,
                                               on_failure="warn"))
    for run_id, r in records.items():
        if r["trajectory"] == "exp1":
            assert r["status"] == "failed", run_id
            assert r["reason"].startswith("monitor python failed: RaisesWhileJoint3Moves.step at t_s 0.502: "
                                          "RuntimeError: torque sensor lost (test_python_monitor.py:")
        else:
            assert r["status"] == "ok" and not r["detected"], run_id


def test_failed_runs_raise_naming_the_first_failure_unless_asked_to_warn(small, tmp_path):
    # Raised after the outputs are written; the records come with the exception.
    with pytest.raises(armfault.RunsFailed) as e:
        armfault.run_campaign(small, monitor=RaisesWhileJoint3Moves, output_dir=tmp_path)
    message = str(e.value)
    assert message.startswith("2 of 4 runs failed; first failed run exp1/kt_degradation#0/-/j3/r0: monitor python "
                              "failed: RaisesWhileJoint3Moves.step at t_s 0.502: RuntimeError: torque sensor lost"), message
    assert f"failed_runs in {tmp_path / 'summary.json'}" in message and 'on_failure="warn"' in message
    assert (e.value.failed, e.value.runs, e.value.run_id) == (2, 4, "exp1/kt_degradation#0/-/j3/r0")
    assert e.value.reason.startswith("monitor python failed: RaisesWhileJoint3Moves.step")
    assert len(e.value.records) == 4 and e.value.output_dir == tmp_path
    assert json.loads((tmp_path / "summary.json").read_text())["failed_runs"]["count"] == 2
    # Warned instead: the same message, and the records returned.
    with pytest.warns(armfault.RunsFailedWarning, match="2 of 4 runs failed; first failed run exp1/"):
        records = armfault.run_campaign(small, monitor=RaisesWhileJoint3Moves, as_frame=False, on_failure="warn")
    assert len(records) == 4
    with pytest.raises(ValueError, match='on_failure: expected "raise" or "warn", got \'ignore\''):
        armfault.run_campaign(small, monitor=RaisesWhileJoint3Moves, on_failure="ignore")


class Garbage(armfault.Monitor):
    """Once joint 3 moves, one verdict that breaks the contract in the way `kind` says."""
    kind = None

    def __init__(self, robot):
        super().__init__(robot)
        self.sent = False

    def step(self, t_s, signals):
        if self.sent or t_s < 1.0 or signals.qd_ref_rad_s[2] == 0:
            return None
        self.sent = True
        ok = dict(joint=3, state="worn", family="friction_increase")
        if self.kind == "joint0":
            return [armfault.Verdict(**{**ok, "joint": 0})]
        if self.kind == "nan":
            return [armfault.Verdict(**ok, magnitude_name="friction_factor", magnitude=math.nan)]
        if self.kind == "backwards":
            return [armfault.Verdict(**ok), armfault.Verdict(**ok, t_s=t_s / 2)]
        if self.kind == "family":
            return armfault.Verdict(**{**ok, "family": "gremlins"})
        if self.kind == "type":
            return 42
        if self.kind == "list of str":
            return ["alarm"]


@pytest.mark.parametrize("kind, reason", [
    ("joint0", "monitor python test_python_monitor.Garbage emitted a bad verdict: verdict 1 (t_s 1, joint 0): joint 0 out of range, expected 1..3"),
    ("nan", "monitor python test_python_monitor.Garbage emitted a bad verdict: verdict 1 (t_s 1, joint 3): magnitude is not a finite number"),
    ("backwards", "monitor python test_python_monitor.Garbage emitted a bad verdict: verdict 2 (t_s 0.5, joint 3): time goes backwards "
                  "(previous verdict at 1 s)"),
    ("family", 'verdict 1 (t_s 1, joint 3): unknown fault family "gremlins"'),
    ("type", "monitor python failed: Garbage.step at t_s 1 returned a int, expected None, an armfault.Verdict "
             "or a list of them"),
    ("list of str", "Garbage.step at t_s 1 returned a list holding a str"),
])
def test_garbage_verdicts_fail_the_run_with_the_contract_checks_reason(small, kind, reason):
    monitor = type("Garbage", (Garbage,), {"kind": kind})
    with pytest.warns(armfault.RunsFailedWarning):
        records = armfault.run_campaign(small, monitor=monitor, as_frame=False, on_failure="warn")
    for r in records:
        if r["trajectory"] == "exp1":
            assert r["status"] == "failed" and reason in r["reason"], (kind, r["reason"])
            assert "Garbage" in r["reason"], (kind, r["reason"])  # names its source, the class
        else:
            assert r["status"] == "ok", (kind, r["run_id"])


def test_records_do_not_depend_on_threads(small):
    one = armfault.run_campaign(small, monitor=TorqueRatioMonitor, threads=1, as_frame=False)
    two = armfault.run_campaign(small, monitor=TorqueRatioMonitor, threads=2, as_frame=False)
    assert one == two


def test_monitor_gets_the_nominal_robot_and_its_own_instance(small):
    seen = []

    class Probe(armfault.Monitor):
        def __init__(self, robot):
            super().__init__(robot)
            seen.append(robot)
            robot["payload_kg"] = 99  # a fresh dict per run: no other run sees this

        def finish(self, t_end_s):
            return armfault.Verdict(1, "healthy")  # at the end of the run

    records = armfault.run_campaign(small, monitor=Probe, threads=1, as_frame=False)
    assert all(r["status"] == "ok" for r in records)
    nominal = armfault.load_campaign(small).robot
    assert len(seen) == 4
    for robot in seen:
        assert {**robot, "payload_kg": nominal["payload_kg"]} == nominal
    with pytest.raises(TypeError, match="not an instance"):
        armfault.run_campaign(small, monitor=Probe(nominal))


def test_a_factory_that_raises_fails_every_run(small):
    def factory(robot):
        raise KeyError("no calibration")

    with pytest.raises(armfault.RunsFailed) as e:
        armfault.run_campaign(small, monitor=factory, as_frame=False)
    records = e.value.records
    assert all(r["status"] == "failed" for r in records)
    assert re.fullmatch(r"run could not be set up: factory\(robot\) raised KeyError: 'no calibration' "
                        r"\(test_python_monitor.py:\d+ in factory\)", records[0]["reason"]), records[0]["reason"]


def test_outputs_name_the_python_monitor(small, tmp_path):
    armfault.run_campaign(small, output_dir=tmp_path, monitor=TorqueRatioMonitor)
    campaign = json.loads((tmp_path / "campaign.json").read_text())
    # Importable by name: recorded by its import path, which `python3 -m armfault` rebuilds.
    assert campaign["campaign"]["monitor"] == {"type": "python", "class": "torque_ratio_monitor:TorqueRatioMonitor",
                                               "settings": {}}
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["campaign"]["monitor"]["type"] == "python"
    assert summary["overall"]["detection"]["successes"] == 1


def test_replay_gives_the_verdicts_the_run_was_scored_from(small):
    campaign = armfault.with_monitor(small, TorqueRatioMonitor)
    trace = armfault.simulate(campaign, "exp1/kt_degradation#0/-/j3/r0")
    verdicts = armfault.replay(TorqueRatioMonitor, trace)
    assert len(verdicts) >= 2  # the alarm, then refined estimates
    for v in verdicts:
        assert (v.joint, v.state, v.alarm, v.family, v.magnitude_name) == (3, "defective", True, "kt_degradation",
                                                                            "kt_factor")
    assert verdicts[0].t_s == trace.record["detection_time_s"]
    assert verdicts[-1].magnitude == trace.record["magnitude_estimate"]  # the latest alarm sizes the fault
    monitor = TorqueRatioMonitor(trace.robot)
    assert armfault.replay(monitor, trace) == verdicts  # an instance is kept, state and all
    assert monitor.reported == verdicts[-1].magnitude
    with pytest.raises(RuntimeError, match="torque sensor lost"):
        armfault.replay(RaisesWhileJoint3Moves, trace)


def test_verdict():
    v = armfault.Verdict(2, "worn", "friction_increase", "friction_factor", 2.5, 0.7)
    assert (v.joint, v.state, v.alarm, v.family, v.t_s) == (2, "worn", True, "friction_increase", None)
    assert armfault.Verdict(1, True).family == "unknown" and armfault.Verdict(1, False).state == "healthy"
    assert armfault.Verdict(1, alarm=True).state == "worn"
    assert armfault.Verdict(1, "healthy", t_s=2.0).to_dict()["t_s"] == 2.0
    assert "friction_factor" in repr(v)
    with pytest.raises(ValueError, match="state must be"):
        armfault.Verdict(1, "broken")
    with pytest.raises(ValueError, match="give its state"):
        armfault.Verdict(1)


def test_step_sees_every_tick_in_order_with_the_traces_values(small):
    seen = []

    class Recorder(armfault.Monitor):
        def step(self, t_s, signals):
            seen.append((t_s, signals.array.copy()))

    trace = armfault.simulate(small, "exp1/healthy/0", monitor=Recorder)
    assert trace.record["status"] == "ok"
    assert [t for t, _ in seen] == list(trace.t_s)
    for k, (_, rows) in enumerate(seen):
        for f, name in enumerate(armfault.SIGNAL_FIELDS):
            assert rows[f].tobytes() == trace.signals[name][k].tobytes(), (k, name)


def test_the_documented_example_is_the_tested_one(small):
    """docs/monitor-api.md shows TorqueRatioMonitor: its code block behaves as the example file."""
    from conftest import REPO
    doc = (REPO / "docs" / "monitor-api.md").read_text()
    blocks = [b.split("```", 1)[0] for b in doc.split("```python\n")[1:]]
    source = next(b for b in blocks if "class TorqueRatioMonitor" in b)
    namespace = {}
    exec(compile(source, "docs/monitor-api.md", "exec"), namespace)
    trace = armfault.simulate(small, "exp1/kt_degradation#0/-/j3/r0")
    assert armfault.replay(namespace["TorqueRatioMonitor"], trace) == armfault.replay(TorqueRatioMonitor, trace)


def test_published_statistics_are_swept_by_tune(small, tmp_path, cli):
    """TorqueRatioMonitor publishes kt_deficit: its runs store it, and `armfault tune` sweeps its
    threshold from the stored runs (docs/monitor-api.md, "Statistics for tune")."""
    from conftest import run_cli
    armfault.run_campaign(small, output_dir=tmp_path, monitor=TorqueRatioMonitor, threads=2)
    decisions = [json.loads(line)["decision"] for line in (tmp_path / "decisions.jsonl").read_text().splitlines()]
    assert all(d["kind"] == "threshold_statistics" for d in decisions), decisions
    assert decisions[0]["statistics"] == [{"name": "kt_deficit", "family": "kt_degradation", "threshold": 0.2,
                                           "setting": ""}]
    done = run_cli(cli, "tune", tmp_path, "--sweep", "kt_deficit=0.1:0.8:8")
    assert done.returncode == 0, done.stderr
    tuning = json.loads((tmp_path / "tuning.json").read_text())
    assert tuning["parameters"][0]["name"] == "kt_deficit"
    summary = json.loads((tmp_path / "summary.json").read_text())
    as_run = tuning["default_point"]
    assert as_run["setting"] == {"kt_deficit": 0.2}
    assert as_run["detection_rate"]["count"] == summary["overall"]["detection"]["successes"] == 1
    assert as_run["false_alarm_rate"]["count"] == summary["overall"]["false_alarm"]["successes"] == 0
    assert "statistic kt_deficit names no setting" in tuning["warnings"][0]
    # The spec names the Python monitor like any type: merge reads the directory; building one
    # from the armfault binary is refused, saying where it runs (python3 -m armfault).
    merged = run_cli(cli, "merge", tmp_path, "-o", tmp_path / "merged")
    assert merged.returncode == 0, merged.stderr
    for name in ("results.jsonl", "decisions.jsonl", "summary.json", "junit.xml", "results.csv"):
        assert (tmp_path / "merged" / name).read_bytes() == (tmp_path / name).read_bytes(), name
    traced = run_cli(cli, "trace", tmp_path / "campaign.json", "--run", "0", "-o", tmp_path / "t.csv")
    assert traced.returncode == 2, traced.stderr
    assert "runs where Python is hosted" in traced.stderr and "python3 -m armfault" in traced.stderr


class Rebinds(TorqueRatioMonitor):
    """Replaces self.values instead of writing into it."""

    def step(self, t_s, signals):
        self.values = self.values.copy()
        return super().step(t_s, signals)


class ZeroThreshold(TorqueRatioMonitor):
    statistics = [armfault.Statistic("kt_deficit", "kt_degradation", 0.0)]


@pytest.mark.parametrize("monitor, reason", [
    (Rebinds, "monitor python failed: Rebinds.values at t_s 0 is another object than at the start: write into it"),
    (ZeroThreshold, "run could not be set up: ZeroThreshold.statistics: statistic 1 (\"kt_deficit\"): threshold 0 is "
                    "not a number > 0"),
])
def test_statistics_that_break_the_contract_fail_the_run(small, monitor, reason):
    with pytest.warns(armfault.RunsFailedWarning):
        records = armfault.run_campaign(small, monitor=monitor, as_frame=False, on_failure="warn")
    assert all(r["status"] == "failed" and r["reason"].startswith(reason) for r in records), records[0]["reason"]


# ---------------------------------------------------------------- commissioning
SEEN = []  # (commissioning as the run's instance first saw it), appended under the GIL


class LearnsMeanCurrent(armfault.Monitor):
    """Learns the mean |i_cmd| of joint 3 over the unit's commissioning run, as JSON."""

    def commission_begin(self):
        self.ticks, self.sum_i = 0, 0.0

    def commission_tick(self, t_s, signals):
        self.ticks += 1
        self.sum_i += abs(signals.i_cmd_A[2])

    def commission_end(self, t_end_s):
        return {"ticks": self.ticks, "mean_i_A": self.sum_i / self.ticks, "t_end_s": t_end_s}

    def step(self, t_s, signals):
        if t_s == 0:
            SEEN.append(json.loads(json.dumps(self.commissioning)))
            if isinstance(self.commissioning, dict):
                self.commissioning["ticks"] = -1  # a run's copy: no other run sees this


class LearnsBytes(LearnsMeanCurrent):
    def commission_end(self, t_end_s):
        return b"\x00unit" + str(self.ticks).encode()

    def step(self, t_s, signals):
        if t_s == 0:
            SEEN.append(self.commissioning)


class RaisesWhileCommissioning(LearnsMeanCurrent):
    def commission_tick(self, t_s, signals):
        if t_s >= 1:
            raise RuntimeError("encoder glitch")


def fleet(small, commissioning=True):
    small["healthy"] = 3
    small["variation"] = {"tolerances": "datasheet", "units": 2}
    small["commissioning"] = commissioning
    return small


def test_commissioning_gives_every_run_its_units_blob(small):
    SEEN.clear()
    records = armfault.run_campaign(fleet(small), monitor=LearnsMeanCurrent, threads=2, as_frame=False)
    assert all(r["status"] == "ok" for r in records), records
    assert len(SEEN) == len(records) == 8
    assert {s["ticks"] for s in SEEN} == {8001}  # 16 s at 500 Hz, both ends; never a run's -1
    assert {s["t_end_s"] for s in SEEN} == {16.0}
    assert len({s["mean_i_A"] for s in SEEN}) == 2  # two units, each its own commissioning

    SEEN.clear()
    armfault.run_campaign(fleet(small), monitor=LearnsBytes, threads=2, as_frame=False)
    assert set(SEEN) == {b"\x00unit8001"}

    SEEN.clear()
    armfault.run_campaign(fleet(small, commissioning=False), monitor=LearnsMeanCurrent, as_frame=False)
    assert SEEN == [None] * 8
    # A monitor without commission_tick learns nothing and runs as before.
    records = armfault.run_campaign(fleet(small), monitor=TorqueRatioMonitor, threads=2, as_frame=False)
    assert all(r["status"] == "ok" for r in records), records


def test_a_commissioning_exception_fails_the_units_runs(small):
    with pytest.raises(armfault.RunsFailed) as e:
        armfault.run_campaign(fleet(small), monitor=RaisesWhileCommissioning, as_frame=False)
    assert e.value.failed == 8
    assert "RaisesWhileCommissioning.commission_tick at t_s 1: RuntimeError: encoder glitch" in e.value.reason, e.value.reason
