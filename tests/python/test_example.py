"""examples/python/calibrate_rig.py as a user runs it: without a display it simulates a rig,
calibrates it with no initial guess, prints the error against the simulator's truth and skips
the Open3D windows; on a virtual display (Debian's xvfb) it opens them and saves what they show."""
import importlib.util
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python",
                       "calibrate_rig.py")


def run_example(*args, launcher=()):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    p = subprocess.run([*launcher, sys.executable, EXAMPLE, *args], capture_output=True, text=True,
                       env=env)
    return p.returncode, p.stdout.replace("\r", "\n"), p.stderr


def test_the_example_calibrates_a_short_drive_and_skips_the_windows():
    code, out, err = run_example("--scenario", "64-32", "--seconds", "2", "--seed", "3")
    assert code == 0, err
    lines = [line.strip() for line in out.splitlines() if line.strip()]
    assert "ok" in lines, out
    m = re.search(r"error against the truth: ([0-9.]+) deg, ([0-9.]+) cm", out)
    assert m, out
    assert float(m.group(1)) < 0.1 and float(m.group(2)) < 1.0, m.group(0)
    assert "the windows are skipped" in out


def test_the_example_names_a_scenario_that_does_not_exist():
    code, out, err = run_example("--scenario", "no-such-rig", "--seconds", "1")
    assert code != 0
    assert "no-such-rig" in err and "Traceback" not in err


def ink(path):
    """Pixels of a saved window that are not the white background, and those of each cloud's
    colour (the base grey 0.6, the target orange (1, 0.5, 0))."""
    import open3d as o3d
    rgb = np.asarray(o3d.io.read_image(path)).astype(int)[:, :, :3]
    near = lambda colour: int((np.abs(rgb - colour).sum(axis=-1) < 40).sum())  # noqa: E731
    return int((rgb.sum(axis=-1) < 740).sum()), near([153, 153, 153]), near([255, 128, 0])


@pytest.mark.skipif(shutil.which("xvfb-run") is None or importlib.util.find_spec("open3d") is None,
                    reason="needs Debian's xvfb and python3-open3d")
def test_the_example_shows_both_clouds_and_the_calibration_overlays_them(tmp_path):
    code, out, err = run_example("--scenario", "64-32", "--seconds", "2", "--seed", "3",
                                 "--screenshots", str(tmp_path), launcher=("xvfb-run", "-a"))
    assert code == 0, err
    assert "the windows are skipped" not in out
    before, after = ink(str(tmp_path / "before.png")), ink(str(tmp_path / "after.png"))
    for name, (total, grey, orange) in (("before", before), ("after", after)):
        assert grey > 1000 and orange > 1000, (name, total, grey, orange)
    # Placed by the calibration, the target's walls and ground fall on the base's: the two clouds
    # cover fewer pixels together than with the target's 37 deg of yaw left unguessed.
    assert after[0] < 0.9 * before[0], (before, after)


def test_the_example_refuses_a_screenshot_folder_that_does_not_exist(tmp_path):
    code, out, err = run_example("--screenshots", str(tmp_path / "missing"))
    assert code != 0
    assert "missing" in err and "no such folder" in err and "Traceback" not in err
