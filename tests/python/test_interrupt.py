"""Ctrl-C stops a long call with KeyboardInterrupt (the C++ work unwinds at its next step)."""
import os
import signal
import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import sys
    import ulc
    drive = ulc.simulate("64-32", seconds=6, decimation=4)
    a, b = drive["lidars"]
    last = []
    def progress(stage, fraction):
        first = "odometry" in stage and (not last or "odometry" not in last[0])
        last[:] = [stage, fraction]
        if first:
            print("odometry started", flush=True)
    try:
        ulc.calibrate(a["frames"], b["frames"], base_times=a["times"], target_times=b["times"],
                      progress=progress)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("KeyboardInterrupt during", last[0], last[1], flush=True)
        sys.exit(3)
""")


def test_ctrl_c_stops_a_calibration():
    p = subprocess.Popen([sys.executable, "-c", SCRIPT], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=os.environ.copy())
    try:
        line = p.stdout.readline()
        assert line.strip() == "odometry started", line + p.stderr.read()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=300)  # a guard against a hang, not a speed test
    finally:
        p.kill()
    assert p.returncode == 3, out + err
    words = out.split()
    assert words[:2] == ["KeyboardInterrupt", "during"] and "finished" not in out
    # Stopped inside the odometry: it had not finished its frames.
    assert "odometry" in out and float(words[-1]) < 1.0, out
