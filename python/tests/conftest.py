"""Shared fixtures of the armfault package's tests. Run with the build tree's package:
PYTHONPATH=build/python /usr/bin/python3 -m pytest -q python/tests (ctest's python_package does)."""
import json
import os
import pathlib
import subprocess
import sys

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "python" / "examples"))

# Joint 3 swings (exp1) or holds while joint 2 swings (j2); a strong K_T loss and a healthy
# run each. Four runs of 3 s.
SMALL = {
    "name": "py-small",
    "seed": 7,
    "robot": "mrr-config1",
    "duration_s": 3,
    "trajectories": [
        {"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}},
        {"name": "j2", "joints": {"2": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 1.0}}},
    ],
    "faults": [{"family": "kt_degradation", "joint": [3], "kt_factor": 0.5, "onset_s": 1.0}],
    "healthy": 1,
    "variation": {"payload_kg": {"uniform": [0.0, 0.5]}, "torque_noise_Nm": {"uniform": [0.02, 0.06]}},
    "floors": {"detection_rate": 0.9, "false_alarm_rate": 0.05},
}


@pytest.fixture
def small():
    return json.loads(json.dumps(SMALL))


@pytest.fixture
def small_file(tmp_path, small):
    path = tmp_path / "small.json"
    path.write_text(json.dumps(small, indent=1))
    return path


@pytest.fixture(scope="session")
def cli():
    """The armfault command of the same build (ARMFAULT_BINARY, set by ctest; else build/armfault)."""
    path = pathlib.Path(os.environ.get("ARMFAULT_BINARY", REPO / "build" / "armfault"))
    if not path.exists():
        pytest.skip(f"no armfault binary at {path}")
    return path


def run_cli(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
