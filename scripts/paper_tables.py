#!/usr/bin/python3
"""Regenerates ULC's side of the paper's simulated experiments (docs/paper.md).

Each experiment runs the benchmarks under the paper's protocol and writes its tables as markdown
into --out (one file per experiment, plus the benchmark's raw output beside it):

  terra-pairs    TERRA on the eight pairs of the paper's figure: single frames (the paper's
                 search, `bench_terra --accuracy`, with scancontext* and FPFH + RANSAC beside it)
                 and 2 s windows (the pipeline's TERRA stage, `bench_terra --windows`)
  terra-n        the lattice size N (the paper's table "impact of sampling number")
  terra-stride   the first stage's search stride
  terra-d1       d1 against the mount's translation, along and across the drive (the paper's
                 figure "impact of translation")
  terra-landscape  eq:feature_dis against the Euclidean distance over a 10 deg grid of rotations
                 (the paper's figure of distance landscapes; PNG slices)
  jeep-refine    scan-scan and JEEP from the paper's disturbance (5 deg, 2 m)
  jeep-maps      JEEP's 6x6 maps of rotation and translation disturbance (PNG pictures)
  jeep-frames    JEEP against its number of frames (PNG pictures)
  hots-refine    HOTS on the six COLORFUL pairs at 60 s (10 runs each: hours)
  time-offset    JEEP and HOTS under a 50 ms clock offset, and the spread against the offset
  peers          registration against PCL and Open3D (built only when they are installed)

Success is the paper's: a rotation initialisation within 10 deg; a calibration within 1 deg and
10 cm. e_rot of the TERRA tables is the mean over the successful samples (the paper's "errors
only recorded when successful"), SR the share of successes.

  scripts/paper_tables.py --bench build_bench/bench --out /tmp/paper --only terra-n,terra-stride
"""
import argparse
import math
import os
import re
import subprocess
import sys

EIGHT_PAIRS = ["64-32", "32-16", "64-horizon", "32-avia", "64-tele", "horizon-tele", "16-tele",
               "32-mid40"]
SAMPLE = re.compile(r"^(\S+) sample \d+: terra ([0-9.]+) deg .*scancontext\* ([0-9.]+) deg"
                    r"(?:, fpfh ([0-9.]+) deg)?")


def run(cmd, log):
    """Runs a benchmark, keeps its output in `log`; returns (stdout, stderr)."""
    print("+", " ".join(cmd), flush=True)
    p = subprocess.run(cmd, capture_output=True, text=True)
    with open(log, "a") as f:
        f.write("$ " + " ".join(cmd) + "\n" + p.stdout + "\n")
    if p.returncode != 0:
        sys.exit(f"paper_tables: {' '.join(cmd)} failed ({p.returncode}):\n{p.stderr[-2000:]}")
    return p.stdout, p.stderr


def sr_and_error(errors, bar=10.0):
    """(SR %, mean error of the successes or None) as the paper counts them."""
    ok = [e for e in errors if e < bar]
    return 100.0 * len(ok) / len(errors), (sum(ok) / len(ok) if ok else None)


def cell(sr, e):
    return f"{sr:.0f} % / " + (f"{e:.2f}" if e is not None else "-")


class Sweep:
    """bench_terra --accuracy over a list of settings, seeds pooled."""

    def __init__(self, bench, threads, seeds, samples, log):
        self.bench, self.threads, self.seeds, self.samples, self.log = (bench, threads, seeds,
                                                                         samples, log)

    def errors(self, pairs, extra):
        pooled = {}
        for seed in self.seeds:
            cmd = [os.path.join(self.bench, "bench_terra"), "--accuracy", "--no-adaptive-d1",
                   "--threads", str(self.threads), "--samples", str(self.samples), "--seed",
                   str(seed), "--pairs", ",".join(pairs)] + extra
            _, err = run(cmd, self.log)
            for line in err.splitlines():
                m = SAMPLE.match(line)
                if m:
                    pooled.setdefault(m.group(1), ([], [], []))
                    for k in range(3):
                        if m.group(k + 2) is not None:
                            pooled[m.group(1)][k].append(float(m.group(k + 2)))
            missing = [p for p in pairs if p not in pooled]
            if missing:
                sys.exit(f"paper_tables: {' '.join(cmd)} gave no samples for "
                         f"{', '.join(missing)} (see {self.log})")
        return pooled


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def terra_pairs(s, args):
    errors = s.errors(EIGHT_PAIRS, ["--fpfh"])
    rows = []
    for p in EIGHT_PAIRS:
        t, sc, fpfh = errors[p]
        rows.append([p, len(t), cell(*sr_and_error(t)), cell(*sr_and_error(sc)),
                     cell(*sr_and_error(fpfh))])
    text = ("Single frames, the paper's search (`bench_terra --accuracy --fpfh`, fixed d1 = 20 m): "
            "SR / mean e_rot (deg) of the successes.\n\n" +
            table(["pair", "samples", "TERRA", "scancontext*", "FPFH + RANSAC"], rows))
    if args.no_windows:
        return text
    for seed in s.seeds:
        out, _ = run([os.path.join(s.bench, "bench_terra"), "--windows", "--seed", str(seed),
                      "--threads", str(s.threads)], s.log)
        text += f"\n2 s windows, seed {seed} (`bench_terra --windows`):\n\n" + out
    return text


def terra_n(s, args):
    pairs = ["64-32", "64-horizon", "64-tele"]
    sizes = [100, 500, 1000, 3000, 10000, 40000]
    results = {n: s.errors(pairs, ["--lattice", str(n)]) for n in sizes}
    header = ["N"] + [str(n) for n in sizes]
    rows = [["cell spacing sqrt(4 pi / N) (deg)"] +
            [f"{math.degrees(math.sqrt(4 * math.pi / n)):.2f}" for n in sizes]]
    for p in pairs:
        rows.append([f"{p}: SR / e_rot"] +
                    [cell(*sr_and_error(results[n][p][0])) for n in sizes])
    return ("The lattice size N, single frames (fixed d1 = 20 m, coarse stride 10 deg): SR / "
            "mean e_rot (deg) of the successes.\n\n" + table(header, rows))


def terra_stride(s, args):
    pairs = ["64-32", "64-horizon", "64-tele"]
    strides = [5, 10, 20, 30]
    results = {d: s.errors(pairs, ["--coarse-stride", str(d)]) for d in strides}
    rows = [[f"{p}: SR / e_rot"] +
            [cell(*sr_and_error(results[d][p][0])) for d in strides]
            for p in pairs]
    return ("The first stage's stride, single frames (N = 10000, fixed d1 = 20 m): SR / mean "
            "e_rot (deg) of the successes.\n\n" +
            table(["coarse stride (deg)"] + [str(d) for d in strides], rows))


def terra_d1(s, args):
    pairs = ["64-32", "64-horizon"]
    offsets = [0.5, 1, 2, 4, 8]
    d1s = [0, 10, 20, 30, 50, 60]
    text = ("d1 against the mount's translation, single frames (N = 10000, stride 10 deg): the "
            "target moved to the base's position plus the offset (`--mount-offset`), keeping its "
            "orientation. SR (%) of the first answer within 10 deg.\n")
    for axis, name in ((0, "along the drive (x)"), (1, "across the drive (y)")):
        results = {}
        for d in offsets:
            offset = [0.0, 0.0, 0.0]
            offset[axis] = d
            for d1 in d1s:
                results[(d, d1)] = s.errors(pairs, ["--mount-offset",
                                                    ",".join(str(v) for v in offset), "--d1",
                                                    str(d1)])
        for p in pairs:
            rows = [[f"{d} m"] + [f"{sr_and_error(results[(d, d1)][p][0])[0]:.0f}" for d1 in d1s]
                    for d in offsets]
            text += f"\n{p}, offset {name}:\n\n" + table(["offset"] + [f"d1 {v} m" for v in d1s],
                                                           rows)
    return text


def existing(commands):
    """An experiment that is a list of benchmark command lines (their markdown tables)."""

    def go(s, args):
        text = ""
        for c in commands:
            argv = [os.path.join(s.bench, c[0])] + c[1:]
            out, _ = run(argv, s.log)
            text += f"`{' '.join([c[0]] + c[1:])}`:\n\n{out}\n"
        return text

    return go


def experiments(images):
    return {
        "terra-pairs": terra_pairs,
        "terra-n": terra_n,
        "terra-stride": terra_stride,
        "terra-d1": terra_d1,
        "terra-landscape": existing([["bench_terra", "--landscape", "--samples", "5", "--png",
                                      images]]),
        "jeep-refine": existing([["bench_jeep", "--accuracy", "--starts", "50", "--threads", "2"]]),
        "colorful-120s": existing([["bench_rig", "--scenarios", "colorful", "--seconds", "120",
                                    "--no-cycles", "--threads", "2"]]),
        "jeep-maps": existing([["bench_jeep", "--robustness", "--threads", "2", "--png", images]]),
        "jeep-frames": existing([["bench_jeep", "--frames-sweep", "--threads", "2", "--png",
                                  images]]),
        "hots-refine": existing([["bench_hots", "--accuracy", "--scenarios",
                                  "64-32,32-16,horizon-tele,64-horizon,32-avia,64-tele", "--runs",
                                  "10", "--seconds", "60"]]),
        "time-offset": existing([["bench_hots", "--time-offset", "--offset-ms", "50",
                                  "--scenarios", "64-32,64-horizon", "--runs", "3", "--seconds",
                                  "60"],
                                 ["bench_hots", "--time-offset", "--offset-ms", "50",
                                  "--scenarios", "64-32", "--seconds", "60", "--runs", "1",
                                  "--spread-png", os.path.join(images, "spread_curve_60s")]]),
        "peers": existing([["bench_peers", "--repeats", "5", "--disturbances", "5", "--threads",
                            "2"]]),
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bench", default="build_bench/bench", help="folder of the bench_* programs")
    p.add_argument("--out", default="/tmp/ulc_paper", help="folder for the tables")
    p.add_argument("--images", default="docs/images", help="folder for the pictures")
    p.add_argument("--only", help="comma-separated experiments (default: all)")
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    p.add_argument("--samples", type=int, default=50, help="TERRA samples per pair and seed")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--no-windows", action="store_true",
                   help="terra-pairs: the single frames only (the 2 s windows take an hour)")
    args = p.parse_args()
    known = experiments(args.images)
    names = args.only.split(",") if args.only else list(known)
    for n in names:
        if n not in known:
            sys.exit(f"paper_tables: unknown experiment '{n}' (known: {', '.join(known)})")
    os.makedirs(args.out, exist_ok=True)
    for n in names:
        log = os.path.join(args.out, n + ".log")
        open(log, "w").close()
        s = Sweep(args.bench, args.threads, args.seeds, args.samples, log)
        text = known[n](s, args)
        with open(os.path.join(args.out, n + ".md"), "w") as f:
            f.write(f"## {n}\n\n{text}")
        print(f"wrote {os.path.join(args.out, n + '.md')}", flush=True)


if __name__ == "__main__":
    main()
