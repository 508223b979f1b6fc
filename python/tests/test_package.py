"""The package itself: import, campaign loading and its errors, the built-in monitor run from
Python against `armfault run`, simulate()."""
import json
import math

import numpy as np
import pandas as pd
import pytest

import armfault
from conftest import REPO, run_cli


def test_import_and_constants(cli):
    assert armfault.__version__ in run_cli(cli, "--version").stdout
    assert armfault.SIGNAL_FIELDS[0] == "q_ref_rad" and "i_cmd_A" in armfault.SIGNAL_FIELDS
    assert len(armfault.SIGNAL_FIELDS) == 9
    assert "kt_degradation" in armfault.FAULT_FAMILIES
    assert armfault.magnitude_key("kt_degradation") == "kt_factor"
    assert issubclass(armfault.InputError, ValueError)


def test_load_campaign_from_file_and_dict(small, small_file):
    from_file = armfault.load_campaign(small_file)
    from_dict = armfault.load_campaign(small)
    assert len(from_file) == len(from_dict) == 4
    assert from_file.name == "py-small" and from_file.duration_s == 3 and from_file.joints == 3
    assert from_file.source == str(small_file) and from_dict.source == "<dict>"
    assert from_file.resolved == from_dict.resolved
    assert from_file.run_ids == [c["run_id"] for c in from_file.cases()]
    assert from_file.monitor["type"] == "power_efficiency"
    assert from_file.robot["modules"][2]["motor"]["kt_Nm_per_A"] > 0
    assert "4 runs" in repr(from_file)


def test_load_errors_name_file_pointer_and_value(small, small_file):
    small["faults"][0]["kt_factor"] = "half"
    with pytest.raises(armfault.InputError) as e:
        armfault.load_campaign(small)
    assert e.value.file == "<dict>"
    assert e.value.pointer == "/faults/0/kt_factor"
    assert "/faults/0/kt_factor" in str(e.value) and "half" in str(e.value)

    # A file: every error listed, each naming the file.
    bad = json.loads(small_file.read_text())
    bad["duration_s"] = -1
    bad["trajectories"][0]["joints"]["3"]["omega_rad_s"] = "fast"
    small_file.write_text(json.dumps(bad))
    with pytest.raises(armfault.InputError) as e:
        armfault.load_campaign(small_file)
    assert e.value.file == str(small_file)
    pointers = [err["pointer"] for err in e.value.errors]
    assert "/duration_s" in pointers and "/trajectories/0/joints/3/omega_rad_s" in pointers
    assert all(line.startswith(str(small_file)) for line in str(e.value).splitlines())

    # What JSON cannot hold is named by its pointer too; a missing file by its name.
    small["faults"][0]["kt_factor"] = float("nan")
    with pytest.raises(armfault.InputError, match="/faults/0/kt_factor: expected a finite number, got nan"):
        armfault.load_campaign(small)
    with pytest.raises(armfault.InputError, match="no-such.json"):
        armfault.load_campaign(small_file.parent / "no-such.json")
    with pytest.raises(TypeError):
        armfault.load_campaign(42)


def test_builtin_monitor_gives_the_cli_records_and_files(cli, small_file, tmp_path):
    done = run_cli(cli, "run", small_file, "-o", tmp_path / "cli", "-q", "-j", "2")
    assert done.returncode in (0, 1), done.stderr
    progress = []
    records = armfault.run_campaign(small_file, output_dir=tmp_path / "py", threads=2, as_frame=False,
                                    progress=lambda done, total: progress.append((done, total)))
    assert progress[-1] == (4, 4)
    for name in ["campaign.json", "results.jsonl", "decisions.jsonl", "results.csv", "summary.json", "junit.xml"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    lines = (tmp_path / "cli" / "results.jsonl").read_text().splitlines()
    assert records == [json.loads(line) for line in lines]
    # The output directory's campaign.json loads as the campaign it ran.
    assert armfault.load_campaign(tmp_path / "py" / "campaign.json").cases() == armfault.load_campaign(small_file).cases()
    # The DataFrame holds the same fields; one thread gives the same records.
    frame = armfault.run_campaign(small_file, threads=1)
    assert isinstance(frame, pd.DataFrame) and list(frame["run_id"]) == [r["run_id"] for r in records]
    expected = pd.DataFrame.from_records([json.loads(line) for line in lines])[frame.columns]
    pd.testing.assert_frame_equal(frame, expected)
    # The summary from records (either shape) is summary.json's.
    written = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert armfault.summary(frame, small_file) == written
    assert armfault.summary(records, small_file) == written
    assert armfault.summary(records)["overall"] == written["overall"]
    # results.csv reads back with integer joints and boolean outcomes, blanks as <NA>.
    table = armfault.read_results_csv(tmp_path / "cli" / "results.csv")
    assert str(table["joint"].dtype) == "Int64" and str(table["detected"].dtype) == "boolean"
    assert str(table["isolated"].dtype) == "boolean" and str(table["seed"].dtype) == "UInt64"
    assert list(table["run_id"]) == [r["run_id"] for r in records]
    for row, record in zip(table.itertuples(), records):
        assert (pd.isna(row.joint) and record["joint"] is None) or row.joint == record["joint"]
        assert bool(row.detected) == record["detected"]
        assert (pd.isna(row.miss_reason) and record["miss_reason"] is None) or row.miss_reason == record["miss_reason"]


def test_trace_and_export_csvs_read_with_their_channels(cli, small_file, tmp_path):
    done = run_cli(cli, "trace", small_file, "--run", "0", "-q", "-o", tmp_path / "t.csv")
    assert done.returncode == 0, done.stderr
    frame, channels = armfault.read_channels(tmp_path / "t.csv")
    assert list(frame.columns)[:3] == ["t_s", "q_ref_rad_j1", "q_rad_j1"]
    by_name = {c["name"]: c for c in channels}
    assert by_name["tau_true_Nm_j3"]["source"] == "truth" and by_name["tau_true_Nm_j3"]["joint"] == 3
    assert by_name["tau_sensor_Nm_j3"]["unit"] == "N m" and by_name["tau_sensor_Nm_j3"]["source"] == "sensor"
    done = run_cli(cli, "export", small_file, "-q", "-o", tmp_path / "exp")
    assert done.returncode == 0, done.stderr
    frame, channels = armfault.read_channels(tmp_path / "exp" / "runs" / "000000.csv.gz")
    # The sensor quantities are the package's SIGNAL_FIELDS, under the trace's names.
    assert [c["quantity"] for c in channels if c["joint"] == 1] == list(armfault.SIGNAL_FIELDS)
    assert {c["name"] for c in channels if c["source"] == "sensor"} >= {"q_ref_rad_j1", "i_cmd_A_j3"}
    assert set(by_name) >= {c["name"] for c in channels if c["quantity"] not in ("qd_ref_rad_s", "winding_temp_C")}
    manifest = armfault.read_results_csv(tmp_path / "exp" / "manifest.csv")
    assert str(manifest["joint"].dtype) == "Int64" and str(manifest["excited"].dtype) == "boolean"


def test_simulate_returns_what_the_monitor_sees(small, cli, small_file, tmp_path):
    campaign = armfault.load_campaign(small)
    trace = armfault.simulate(campaign, "exp1/healthy/0")
    n = len(trace.t_s)
    assert trace.t_s.shape == (n,) and n == pytest.approx(3 * 500, abs=2)
    assert np.allclose(np.diff(trace.t_s), 0.002)  # 500 Hz controller ticks, seconds
    assert set(trace.signals) == set(armfault.SIGNAL_FIELDS)
    for name, values in trace.signals.items():
        assert values.shape == (n, 3) and values.dtype == np.float64, name
    q_ref = trace.signals["q_ref_rad"][:, 2]
    assert 0.1 < np.abs(q_ref).max() < 1.0  # radians: a 25 degree swing
    assert np.abs(trace.signals["q_meas_rad"][:, 2] - q_ref).max() < math.radians(2)
    assert np.all(trace.signals["v_bus_meas_V"] == 70.0)
    assert np.abs(trace.signals["i_cmd_A"]).max() <= 6.0  # the DAC's command range
    assert np.abs(trace.signals["tau_sensor_Nm"][:, 2]).max() < 28.0
    assert np.all(np.isnan(trace.signals["winding_temp_C"]))  # mrr-config1 has no winding sensor
    assert trace.signals["qd_ref_rad_s"][:, 0].max() == 0  # joint 1 holds
    assert trace.frame(3)["i_cmd_A"].equals(pd.Series(trace.signals["i_cmd_A"][:, 2], name="i_cmd_A"))
    # The record is the campaign's, and names the truth.
    assert trace.record["run_id"] == "exp1/healthy/0" and trace.record["family"] is None
    faulty = armfault.simulate(campaign, 0)
    assert faulty.record["family"] == "kt_degradation" and faulty.record["onset_s"] == 1.0
    run_cli(cli, "run", small_file, "-o", tmp_path / "cli", "-q")
    lines = (tmp_path / "cli" / "results.jsonl").read_text().splitlines()
    assert faulty.record == json.loads(lines[0])
    with pytest.raises(armfault.InputError, match='did you mean "exp1/healthy/0"'):
        armfault.simulate(campaign, "exp1/healthy/9")
    with pytest.raises(armfault.InputError, match="0..3"):
        armfault.simulate(campaign, 4)
