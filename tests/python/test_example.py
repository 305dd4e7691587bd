"""examples/python/calibrate_rig.py as a user runs it, without a display: it simulates a rig,
calibrates it with no initial guess, prints the error against the simulator's truth and skips
the Open3D windows."""
import os
import re
import subprocess
import sys

EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python",
                       "calibrate_rig.py")


def run_example(*args):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    p = subprocess.run([sys.executable, EXAMPLE, *args], capture_output=True, text=True, env=env)
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
