"""A Python monitor named in campaign.json by import path ({"type": "python", "class":
"package.module:Class", "settings": {...}}), rebuilt by `python3 -m armfault` for run, trace
--run and the rest without the caller passing the class (docs/monitor-api.md, "A monitor in
Python"); and `trace --statistics` for a Python monitor."""
import csv
import json
import os
import pathlib
import subprocess
import sys

import pytest

import armfault
from conftest import REPO, run_cli
from torque_ratio_monitor import TorqueRatioMonitor

CLASS = "torque_ratio_monitor:TorqueRatioMonitor"

# A subclass whose threshold is a setting (self.settings, set before __init__ runs), declared at
# the statistic's `setting` pointer so that tune writes the tuned value back into it.
SETTINGS_MONITOR = '''
import armfault
from torque_ratio_monitor import TorqueRatioMonitor


class Tunable(TorqueRatioMonitor):
    def __init__(self, robot):
        self.DEFICIT = float(self.settings.get("kt_deficit", 0.2))
        self.statistics = [armfault.Statistic("kt_deficit", "kt_degradation", self.DEFICIT, "/kt_deficit")]
        super().__init__(robot)


def not_a_class(robot):
    return None


class NotAMonitor:
    pass
'''


def python_cli(*args, cwd=None):
    """`python3 -m armfault ARGS` with this package and the examples importable."""
    env = dict(os.environ)
    paths = [str(REPO / "python" / "examples")] + [os.path.abspath(p) for p in env.get("PYTHONPATH", "").split(os.pathsep)
                                                   if p]
    env["PYTHONPATH"] = os.pathsep.join(paths)
    return subprocess.run([sys.executable, "-m", "armfault", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env)


@pytest.fixture
def class_file(tmp_path, small):
    small["monitor"] = {"type": "python", "class": CLASS}
    path = tmp_path / "small.json"
    path.write_text(json.dumps(small, indent=1))
    return path


def test_run_from_the_command_line_is_run_campaign_byte_for_byte(class_file, small, tmp_path):
    done = python_cli("run", class_file, "-o", tmp_path / "cli", "-j", "2", "-q")
    assert done.returncode == 0, done.stderr
    one = python_cli("run", class_file, "-o", tmp_path / "cli1", "-j", "1", "-q")
    assert one.returncode == 0, one.stderr
    armfault.run_campaign(small, output_dir=tmp_path / "py", monitor=TorqueRatioMonitor, threads=2)
    for name in ("campaign.json", "results.jsonl", "decisions.jsonl", "summary.json"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "cli1" / name).read_bytes(), name
    for name in ("results.jsonl", "decisions.jsonl"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes(), name
    resolved = json.loads((tmp_path / "cli" / "campaign.json").read_text())["campaign"]["monitor"]
    assert resolved == {"type": "python", "class": CLASS, "settings": {}}
    # run_campaign of the campaign file builds the class itself, without monitor=.
    records = armfault.run_campaign(class_file, as_frame=False)
    lines = (tmp_path / "cli" / "results.jsonl").read_text().splitlines()
    assert [json.loads(line) for line in lines] == records


def test_trace_run_rebuilds_the_class_and_shows_its_statistics(class_file, tmp_path):
    assert python_cli("run", class_file, "-o", tmp_path / "out", "-q").returncode == 0
    records = [json.loads(line) for line in (tmp_path / "out" / "results.jsonl").read_text().splitlines()]
    kt = next(r for r in records if r["family"] == "kt_degradation" and r["trajectory"] == "exp1")
    healthy = next(r for r in records if not r["family"] and r["trajectory"] == "exp1")
    for record in (kt, healthy):
        done = python_cli("trace", tmp_path / "out" / "campaign.json", "--run", record["run_id"], "-o",
                          tmp_path / "t.csv", "--statistics", tmp_path / "s.csv")
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout.split("record: ")[1].splitlines()[0]) == record  # as the campaign ran it
        assert "statistics: kt_deficit -> " in done.stdout
        with open(tmp_path / "s.csv") as f:
            rows = list(csv.DictReader(f))
        assert list(rows[0]) == ["t_s", "joint", "statistic", "family", "value", "threshold", "above"]
        assert {r["statistic"] for r in rows} == {"kt_deficit"}
        assert {r["threshold"] for r in rows} == {"0.2"}
        top = [r for r in rows if r["joint"] == "3" and r["value"]]
        assert top, "the monitor publishes the top joint's statistic"
        above = [float(r["t_s"]) for r in top if r["above"] == "1"]
        if record is kt:
            # Crosses its threshold after the onset, first at the run's detection.
            assert above and min(above) == record["detection_time_s"] and min(above) >= record["onset_s"]
        else:
            assert not above
            assert max(float(r["value"]) for r in top) <= 0.2


def test_tune_writes_the_tuned_threshold_into_the_classes_settings(small, tmp_path):
    (tmp_path / "tunable.py").write_text(SETTINGS_MONITOR)
    small["monitor"] = {"type": "python", "class": "tunable:Tunable", "settings": {"kt_deficit": 0.3}}
    (tmp_path / "c.json").write_text(json.dumps(small))
    # The module is imported from the current directory, as Python imports under -m.
    done = python_cli("run", "c.json", "-o", "out", "-q", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    decision = json.loads((tmp_path / "out" / "decisions.jsonl").read_text().splitlines()[0])["decision"]
    assert decision["statistics"][0]["threshold"] == 0.3  # self.settings reached __init__
    tuned = python_cli("tune", "out", "--sweep", "kt_deficit=0.1:0.8:8", cwd=tmp_path)
    assert tuned.returncode == 0, tuned.stderr
    monitor = json.loads((tmp_path / "out" / "tuned-monitor.json").read_text())
    assert monitor["type"] == "python" and monitor["class"] == "tunable:Tunable"
    tuning = json.loads((tmp_path / "out" / "tuning.json").read_text())
    assert monitor["settings"]["kt_deficit"] == tuning["operating_point"]["setting"]["kt_deficit"]
    assert not any("names no setting" in w for w in tuning.get("warnings", []))
    # The tuned monitor runs as it is.
    small["monitor"] = "out/tuned-monitor.json"
    (tmp_path / "tuned.json").write_text(json.dumps(small))
    again = python_cli("run", "tuned.json", "-o", "again", "-q", cwd=tmp_path)
    assert again.returncode in (0, 1), again.stderr


@pytest.mark.parametrize("value, message", [
    ("no_such_module_xyz:M", 'cannot import module "no_such_module_xyz": ModuleNotFoundError'),
    ("tunable:Tunabel", 'module "tunable" has no "Tunabel"; did you mean "tunable:Tunable"?'),
    ("tunable:not_a_class", "is a function, not a class: name a subclass of armfault.Monitor"),
    ("tunable:NotAMonitor", "is the class NotAMonitor, which is not a subclass of armfault.Monitor"),
    ("tunable.py", 'expected an import path "package.module:Class"'),
])
def test_a_class_that_cannot_be_built_is_exit_2_naming_the_field_and_value(small, tmp_path, value, message):
    (tmp_path / "tunable.py").write_text(SETTINGS_MONITOR)
    small["monitor"] = {"type": "python", "class": value}
    (tmp_path / "c.json").write_text(json.dumps(small))
    for command in (["run", "c.json", "-o", "out", "-q"], ["trace", "c.json", "--run", "0", "-o", "t.csv"],
                    ["validate", "c.json", "--load-plugins"]):
        done = python_cli(*command, cwd=tmp_path)
        assert done.returncode == 2, (command, done.stdout, done.stderr)
        assert "c.json: /monitor/class: " in done.stderr, done.stderr
        assert value in done.stderr and message in done.stderr, done.stderr
    with pytest.raises(armfault.InputError) as error:
        sys.path.insert(0, str(tmp_path))
        try:
            armfault.load_campaign(tmp_path / "c.json")
        finally:
            sys.path.remove(str(tmp_path))
    assert error.value.pointer == "/monitor/class" and message in str(error.value)


def test_the_binary_names_the_command_that_runs_a_python_class(class_file, tmp_path, cli):
    done = run_cli(cli, "trace", class_file, "--run", "0", "-o", tmp_path / "t.csv")
    assert done.returncode == 2
    assert "/monitor/class: the Python monitor \"" + CLASS + "\" runs where Python is hosted" in done.stderr
    assert "python3 -m armfault" in done.stderr
    # Reading the spec needs no Python: validate (without --load-plugins) checks it.
    assert run_cli(cli, "validate", class_file).returncode == 0


def test_a_class_that_cannot_be_imported_by_name_is_recorded_as_a_factory(small, tmp_path):
    class Local(armfault.Monitor):
        pass

    armfault.run_campaign(small, output_dir=tmp_path, monitor=Local, on_failure="warn")
    monitor = json.loads((tmp_path / "campaign.json").read_text())["campaign"]["monitor"]
    assert monitor == {"type": "python", "factory": Local.__module__ + "." + Local.__qualname__}
    done = python_cli("trace", tmp_path / "campaign.json", "--run", "0", "-o", tmp_path / "t.csv")
    assert done.returncode == 2
    assert "/monitor/factory: a Python monitor passed to run_campaign" in done.stderr


def test_replay_of_an_export_through_a_python_monitor_is_its_run(class_file, cli, tmp_path):
    """`python3 -m armfault replay`: the export's signals through the Python class named in its
    campaign.json give the campaign's run line for line; the binary says where it runs."""
    assert python_cli("run", class_file, "-o", tmp_path / "run", "-q").returncode == 0
    done = python_cli("export", class_file, "-o", tmp_path / "x", "-q")
    assert done.returncode == 0, done.stderr
    done = python_cli("replay", tmp_path / "x", "-o", tmp_path / "r", "-j", "2", "-q")
    assert done.returncode == 0, done.stderr
    assert "alarms per hour of operation" in done.stdout
    for name in ("results.jsonl", "decisions.jsonl", "campaign.json"):
        assert (tmp_path / "r" / name).read_bytes() == (tmp_path / "run" / name).read_bytes(), name
    done = run_cli(cli, "replay", tmp_path / "x", "-o", tmp_path / "b")
    assert done.returncode == 2
    assert "/monitor/class" in done.stderr and "python3 -m armfault" in done.stderr
