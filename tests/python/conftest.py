"""Fixtures of the Python module's tests: the module from the build folder (PYTHONPATH, set by
CTest), the `ulc` command (ULC_APP) and a short simulated drive written by `ulc simulate`."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import pytest

import ulc

ULC_APP = os.environ.get("ULC_APP", "ulc")


def run_ulc(*args):
    """Runs the `ulc` command; returns (exit code, stdout, stderr)."""
    p = subprocess.run([ULC_APP, *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


@pytest.fixture(scope="session")
def drive():
    """A 0.6 s drive of the 64-32 rig (six frames per LiDAR), as the command-line tests use."""
    folder = tempfile.mkdtemp(prefix="ulc_python_")
    code, out, err = run_ulc("simulate", "--quiet", "--scenario", "64-32", "--seconds", "0.6",
                             "--seed", "2", "--out", folder)
    assert code == 0, err
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


def lidar(folder, name):
    return os.path.join(folder, name)


def truth(folder, base="lidar64", target="lidar32"):
    with open(os.path.join(folder, "ground_truth.json")) as f:
        doc = json.load(f)
    for p in doc["pairs"]:
        if p["base"] == base and p["target"] == target:
            return np.array(p["T_base_target"])
    raise KeyError(f"{base} -> {target}")


def errors(T, T_true):
    """Rotation (deg) and translation (m) errors of T against T_true."""
    E = np.linalg.inv(T_true) @ T
    angle = np.degrees(np.arccos(np.clip((np.trace(E[:3, :3]) - 1) / 2, -1, 1)))
    return angle, np.linalg.norm(E[:3, 3])


TIMING_KEYS = ("seconds", "timing_s", "descriptor_seconds", "odometry_seconds")


def without_timings(value):
    """A result document without its wall-clock fields (they differ between any two runs)."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items()
                if k not in TIMING_KEYS and not k.endswith("_seconds")}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value
