#!/usr/bin/python3
"""What HOTS's cross links say of right and wrong extrinsics, registration by registration.

For each scenario and seed: simulate a drive (kept in --work), run HOTS alone (`ulc calibrate
--stages hots --synced-clocks`) from the true extrinsic and from wrong ones, and read every
cross-link registration from the result file (stages.hots.cross_link_registrations). Prints one
row per run: how many registrations converged, how many of those moved less than the agree
bounds (1 deg and 1 m), and the same among those whose inlier ratio reaches --floor.
docs/experiments/tele_cross_links.md reads it.

  /usr/bin/python3 scripts/cross_link_census.py --ulc build/apps/ulc/ulc --work /tmp/census \
      --scenarios 64-tele,horizon-tele,16-tele --seeds 1-3
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys

AGREE_DEG, AGREE_M = 1.0, 1.0

# Wrong starts: (name, metres along the target's x, degrees added to yaw, degrees added to pitch).
STARTS = [("truth", 0, 0, 0), ("x+1m", 1, 0, 0), ("x+2m", 2, 0, 0), ("yaw+3", 0, 3, 0),
          ("pitch+2", 0, 0, 2)]


def rpy_deg(r):
    """Roll, pitch, yaw (deg) of R = Rz(yaw) Ry(pitch) Rx(roll), as `--initial` reads them."""
    return [math.degrees(math.atan2(r[2][1], r[2][2])),
            math.degrees(math.asin(max(-1.0, min(1.0, -r[2][0])))),
            math.degrees(math.atan2(r[1][0], r[0][0]))]


def start_text(t, along_x, yaw, pitch):
    xyz = [t[i][3] + along_x * t[i][0] for i in range(3)]
    roll_pitch_yaw = rpy_deg(t)
    roll_pitch_yaw[1] += pitch
    roll_pitch_yaw[2] += yaw
    return " ".join("%.6f" % v for v in xyz + roll_pitch_yaw)


def simulate(ulc, scenario, seed, seconds, folder):
    if not os.path.exists(os.path.join(folder, "ground_truth.json")):
        subprocess.run([ulc, "simulate", "--scenario", scenario, "--seconds", str(seconds),
                        "--seed", str(seed), "--out", folder, "--quiet"], check=True,
                       stdout=subprocess.DEVNULL)
    with open(os.path.join(folder, "ground_truth.json")) as f:
        return json.load(f)["pairs"][0]


def hots_alone(ulc, folder, pair, initial, out):
    if os.path.exists(out):
        os.remove(out)  # a stale file from an earlier run must not stand in for this one
    run = subprocess.run([ulc, "calibrate", "--base", os.path.join(folder, pair["base"]),
                          "--target", os.path.join(folder, pair["target"]), "--synced-clocks",
                          "--stages", "hots", "--threads", "2", "--initial", initial, "--output",
                          out, "--quiet"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         text=True)
    if run.returncode not in (0, 1) or not os.path.exists(out):  # 1: ran, and HOTS refused
        sys.exit("ulc calibrate on %s failed (exit %d): %s" % (folder, run.returncode, run.stderr))
    with open(out) as f:
        entry = json.load(f)["results"][0]
    return entry["status"], entry["stages"]["hots"]["cross_link_registrations"]["rows"]


def summary(rows, floor):
    converged = [r for r in rows if r[1] == 1]
    weak = [r for r in converged if r[2] >= floor]
    agree = lambda rs: sum(1 for r in rs if r[3] < AGREE_DEG and r[4] < AGREE_M)
    ratio = statistics.median([r[2] for r in converged]) if converged else 0.0
    return len(rows), len(converged), agree(converged), len(weak), agree(weak), ratio


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--ulc", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--scenarios", default="64-tele,horizon-tele,16-tele")
    p.add_argument("--seeds", default="1-3", help="first-last")
    p.add_argument("--seconds", type=float, default=20)
    p.add_argument("--floor", type=float, default=0.1)
    a = p.parse_args()
    first, last = (int(v) for v in a.seeds.split("-"))
    os.makedirs(a.work, exist_ok=True)
    print("| pair | seed | start | status | attempted | converged | agreeing | ratio >= %.2f |"
          " agreeing | inlier ratio (median) |" % a.floor)
    print("|---|---:|---|---|---:|---:|---:|---:|---:|---:|")
    for scenario in a.scenarios.split(","):
        for seed in range(first, last + 1):
            folder = os.path.join(a.work, "%s_s%d" % (scenario, seed))
            pair = simulate(a.ulc, scenario, seed, a.seconds, folder)
            for name, along_x, yaw, pitch in STARTS:
                initial = start_text(pair["T_base_target"], along_x, yaw, pitch)
                out = os.path.join(a.work, "%s_s%d_%s.json" % (scenario, seed, name))
                status, rows = hots_alone(a.ulc, folder, pair, initial, out)
                n, conv, agr, weak, weak_agr, ratio = summary(rows, a.floor)
                print("| %s | %d | %s | %s | %d | %d | %d | %d | %d | %.3f |" %
                      (scenario, seed, name, status, n, conv, agr, weak, weak_agr, ratio))
                sys.stdout.flush()


if __name__ == "__main__":
    main()
