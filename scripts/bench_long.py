#!/usr/bin/python3
"""Peak memory and wall time of `ulc calibrate` against drive length (docs/BENCHMARKS.md,
"Long drives").

For each length (minutes) it simulates the 64-32 town drive at 10 Hz (`ulc simulate --seconds`,
seed 1) unless the folder is already there, calibrates it with every default stage and no initial
guess (`ulc calibrate --threads N`, under /usr/bin/time -v), scores the result against the
ground truth (`ulc evaluate --json`) and prints one row per drive: peak resident memory, wall
time, CPU time (user + system: the work, less sensitive than the wall time to other jobs on the
machine), the load average at the end, the survey's time, the stretch calibrated on, e_rot,
e_trans and the clock offset's error. --svg draws memory and time against length. Simulated drives take about 1.3 GB of disk per minute: --remove deletes
each one after its row; --merge adds the rows of earlier runs (their --json) to the plot.

  scripts/bench_long.py --ulc build/apps/ulc/ulc --minutes 1 2 5 10 --work /tmp/long \
      --threads 2 --svg docs/images/long_drives.svg
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys


def simulate(ulc, folder, seconds):
    if os.path.isdir(folder):
        return
    subprocess.run([ulc, "simulate", "--scenario", "64-32", "--seconds", str(seconds),
                    "--out", folder, "--quiet"], check=True)


def time_v(field, text):
    m = re.search(re.escape(field) + r": (.*)", text)
    if not m:
        sys.exit(f"bench_long: /usr/bin/time printed no '{field}'")
    return m.group(1).strip()


def wall_seconds(text):
    parts = [float(p) for p in time_v("Elapsed (wall clock) time (h:mm:ss or m:ss)", text).split(":")]
    seconds = 0.0
    for p in parts:
        seconds = seconds * 60 + p
    return seconds


def calibrate(ulc, folder, threads, budget):
    result = os.path.join(folder, "result.json")
    cmd = ["/usr/bin/time", "-v", ulc, "calibrate", "--base", os.path.join(folder, "lidar64"),
           "--target", os.path.join(folder, "lidar32"), "--threads", str(threads), "--quiet",
           "--output", result]
    if budget is not None:
        cmd += ["--budget", str(budget)]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode not in (0, 1):
        sys.exit(f"bench_long: {' '.join(cmd)} failed:\n{run.stderr}")
    evaluation = subprocess.run([ulc, "evaluate", "--result", result, "--ground-truth",
                                 os.path.join(folder, "ground_truth.json"), "--json"],
                                capture_output=True, text=True)
    entry = json.load(open(result))["results"][0]
    return {
        "peak_gb": int(time_v("Maximum resident set size (kbytes)", run.stderr)) / 1024 ** 2,
        "wall_s": wall_seconds(run.stderr),
        "cpu_s": float(time_v("User time (seconds)", run.stderr)) +
                 float(time_v("System time (seconds)", run.stderr)),
        "load": os.getloadavg()[0],
        "status": entry["status"],
        "selection": entry["stages"].get("selection"),
        "evaluation": json.loads(evaluation.stdout) if evaluation.returncode in (0, 1) else None,
        "timing_s": entry["timing_s"],
    }


def svg_plot(rows, path):
    """Two panels: peak memory (GB) and wall time (s) against drive length (min)."""
    width, height, pad = 760, 300, 50
    panel = (width - 3 * pad) / 2
    top, bottom = 30, height - pad
    xs = [r["minutes"] for r in rows]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           'font-family="sans-serif" font-size="12">',
           '<rect width="100%" height="100%" fill="white"/>']

    def draw(x0, series, label):
        """series: (key, legend, colour) drawn on one panel."""
        ymax = max(r[key] for key, _, _ in series for r in rows) * 1.2
        xmax = max(xs) * 1.05
        px = lambda x: x0 + x / xmax * panel
        py = lambda y: bottom - y / ymax * (bottom - top)
        out.append(f'<line x1="{x0}" y1="{bottom}" x2="{x0 + panel}" y2="{bottom}" stroke="black"/>')
        out.append(f'<line x1="{x0}" y1="{top}" x2="{x0}" y2="{bottom}" stroke="black"/>')
        out.append(f'<text x="{x0 + panel / 2}" y="{top - 10}" text-anchor="middle">{label}</text>')
        out.append(f'<text x="{x0 + panel / 2}" y="{height - 12}" text-anchor="middle">'
                   'drive length (min)</text>')
        for x in xs:
            out.append(f'<text x="{px(x)}" y="{bottom + 16}" text-anchor="middle">{x:g}</text>')
        for k in range(5):
            y = ymax * k / 4
            out.append(f'<text x="{x0 - 6}" y="{py(y) + 4}" text-anchor="end">{y:.3g}</text>')
            out.append(f'<line x1="{x0}" y1="{py(y)}" x2="{x0 + panel}" y2="{py(y)}" '
                       'stroke="#ddd"/>')
        for n, (key, legend, colour) in enumerate(series):
            ys = [r[key] for r in rows]
            points = " ".join(f"{px(x)},{py(y)}" for x, y in zip(xs, ys))
            out.append(f'<polyline points="{points}" fill="none" stroke="{colour}" '
                       'stroke-width="2"/>')
            for x, y in zip(xs, ys):
                out.append(f'<circle cx="{px(x)}" cy="{py(y)}" r="4" fill="{colour}"/>')
            out.append(f'<text x="{x0 + 10}" y="{top + 14 + 16 * n}" fill="{colour}">{legend}</text>')

    draw(pad, [("peak_gb", "peak resident memory", "#1f77b4")], "peak memory (GB)")
    draw(2 * pad + panel, [("wall_s", "wall", "#d62728"), ("cpu_s", "CPU (user + system)", "#2ca02c")],
         "time of ulc calibrate (s)")
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--ulc", required=True)
    p.add_argument("--minutes", type=float, nargs="+", default=[1, 2, 5, 10])
    p.add_argument("--work", default="/tmp/bench_long")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--budget", type=float, help="--budget of ulc calibrate (default: its own)")
    p.add_argument("--svg")
    p.add_argument("--json", help="write the rows here")
    p.add_argument("--remove", action="store_true", help="delete each simulated drive after use")
    p.add_argument("--merge", nargs="+", default=[],
                   help="--json files of earlier runs: their rows join the plot and the --json")
    a = p.parse_args()
    rows = []
    print(f"{'min':>5} {'peak GB':>8} {'wall s':>7} {'cpu s':>7} {'load':>5} {'survey s':>8} "
          f"{'stretch s':>11} {'e_rot deg':>10} {'e_trans cm':>10} {'dt err ms':>9} status")
    for minutes in a.minutes:
        folder = os.path.join(a.work, f"drive_{minutes:g}min")
        simulate(a.ulc, folder, minutes * 60)
        row = calibrate(a.ulc, folder, a.threads, a.budget)
        row["minutes"] = minutes
        rows.append(row)
        sel = row["selection"]
        stretch = f"{sel['start_s']:.0f}-{sel['end_s']:.0f}" if sel and sel["applied"] else "all"
        row["survey_s"] = sel["seconds"] if sel else 0.0
        ev = row["evaluation"]["pairs"][0] if row["evaluation"] else {}
        print(f"{minutes:5g} {row['peak_gb']:8.2f} {row['wall_s']:7.1f} {row['cpu_s']:7.1f} "
              f"{row['load']:5.1f} {row['survey_s']:8.1f} "
              f"{stretch:>11} "
              f"{ev.get('e_rot_deg', float('nan')):10.4f} "
              f"{ev.get('e_trans_m', float('nan')) * 100:10.2f} "
              f"{ev.get('time_offset_error_s', float('nan')) * 1e3:9.2f} {row['status']}",
              flush=True)
        if a.remove:
            shutil.rmtree(folder)
    for path in a.merge:
        with open(path) as f:
            rows += json.load(f)
    rows.sort(key=lambda r: r["minutes"])
    if a.svg:
        svg_plot(rows, a.svg)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
