#!/usr/bin/env python3
"""The cost of calling the pipeline from Python rather than from C++ (issue 35: < 2 %).

One drive (a dataset folder of `ulc simulate`), calibrated in turn, --repeats times:
  cli    `ulc calibrate --base A --target B --output r.json --quiet`: the C++ program, process
         start, reading the frames and writing the result file included;
  path   ulc.calibrate(A, B).write(r.json) in this process: the same reading, pipeline and
         writer behind the Python call;
  numpy  ulc.calibrate(frames_a, frames_b, base_times=..., target_times=...) on float32 arrays
         read beforehand (not timed): the conversion into the pipeline's clouds, the GIL and the
         result object against the pipeline's own time of the same call (timing_s.total),
         with a progress callback that records the longest wait between two calls: how long
         Ctrl-C may wait (it is checked at each call).
Prints each run and the medians; the ratios are taken within each round (same load).

--memory instead measures what the numpy call adds to the process's resident memory: the arrays
are read (float32) in a fresh process, its peak is reset (/proc/self/clear_refs), the call
runs, and the peak above the resident memory before the call is printed beside the arrays' size.

  PYTHONPATH=build_bench/python python3 bench/python_overhead.py --ulc build_bench/apps/ulc/ulc \
      --drive /tmp/64-32-60 --threads 2 --repeats 3
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

import numpy as np

import ulc


def timed(f):
    start = time.perf_counter()
    value = f()
    return time.perf_counter() - start, value


def cli_run(args, out):
    cmd = [args.ulc, "calibrate", "--quiet", "--base", os.path.join(args.drive, args.base),
           "--target", os.path.join(args.drive, args.target), "--output", out,
           "--threads", str(args.threads)]
    seconds, p = timed(lambda: subprocess.run(cmd, capture_output=True, text=True))
    if p.returncode not in (0, 1):
        raise SystemExit(p.stderr)
    with open(out) as f:
        return seconds, json.load(f)["results"][0]


def path_run(args, out):
    def call():
        r = ulc.calibrate(os.path.join(args.drive, args.base),
                          os.path.join(args.drive, args.target), threads=args.threads)
        r.write(out)
        return r
    return timed(call)


class LongestWait:
    """progress(stage, fraction) that keeps the longest time between two calls."""

    def __init__(self):
        self.last = time.perf_counter()
        self.longest, self.where = 0.0, ""

    def __call__(self, stage, fraction):
        now = time.perf_counter()
        if now - self.last > self.longest:
            self.longest, self.where = now - self.last, f"{stage} {fraction:.2f}"
        self.last = now


def numpy_run(args, frames):
    a, b = frames
    wait = LongestWait()
    seconds, result = timed(lambda: ulc.calibrate(
        a["frames"], b["frames"], base_times=a["times"], target_times=b["times"],
        names=[args.base, args.target], threads=args.threads, progress=wait))
    return seconds, result, wait


def as_float32(lidar):
    return {"frames": [f.astype(np.float32) for f in lidar["frames"]], "times": lidar["times"]}


def status_kib(field):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise SystemExit(f"python_overhead: /proc/self/status has no {field}")


def memory_run(args):
    """Peak resident memory the numpy call adds, in this process (see --memory)."""
    frames = [as_float32(ulc.read_frames(os.path.join(args.drive, n)))
              for n in (args.base, args.target)]
    arrays_gb = sum(f.nbytes for lidar in frames for f in lidar["frames"]) / 1e9
    before_kib = status_kib("VmRSS")
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # resets VmHWM to the current resident size
    seconds, result, _ = numpy_run(args, frames)
    peak_kib = status_kib("VmHWM")
    row = dict(arrays_gb=arrays_gb, rss_before_gb=before_kib * 1024 / 1e9,
               peak_gb=peak_kib * 1024 / 1e9, added_gb=(peak_kib - before_kib) * 1024 / 1e9,
               seconds=seconds, success=bool(result.success))
    print(" ".join(f"{k}={v:.3f}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()))
    if args.json:
        print(json.dumps(row))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ulc", required=True, help="the ulc program")
    p.add_argument("--drive", required=True, help="dataset folder of `ulc simulate`")
    p.add_argument("--base", default="lidar64")
    p.add_argument("--target", default="lidar32")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--json", action="store_true", help="print the figures as JSON too")
    p.add_argument("--memory", action="store_true",
                   help="the resident memory the numpy call adds (one call, no timing rounds)")
    args = p.parse_args()
    if args.memory:
        memory_run(args)
        return

    out = os.path.join(tempfile.mkdtemp(prefix="ulc_overhead_"), "r.json")
    frames = [as_float32(ulc.read_frames(os.path.join(args.drive, n)))
              for n in (args.base, args.target)]
    rows = []
    print(f"{'round':>5} {'cli_s':>8} {'path_s':>8} {'path/cli':>9} {'numpy_s':>8} "
          f"{'pipeline_s':>10} {'numpy/pipeline':>15} {'longest_wait_s':>14} same_extrinsic "
          f"wait_ends_at")
    for k in range(args.repeats):
        cli_s, cli_entry = cli_run(args, out)
        path_s, path_result = path_run(args, out)
        numpy_s, numpy_result, wait = numpy_run(args, frames)
        pipeline_s = numpy_result.timing_s["total"]
        same = (np.array(cli_entry["T_base_target"]) == path_result.T_base_target).all() \
            and (path_result.T_base_target == numpy_result.T_base_target).all()
        rows.append(dict(cli_s=cli_s, path_s=path_s, path_ratio=path_s / cli_s, numpy_s=numpy_s,
                         pipeline_s=pipeline_s, numpy_ratio=numpy_s / pipeline_s,
                         longest_wait_s=wait.longest, wait_ends_at=wait.where,
                         same_extrinsic=bool(same)))
        r = rows[-1]
        print(f"{k:>5} {cli_s:8.2f} {path_s:8.2f} {r['path_ratio']:9.4f} {numpy_s:8.2f} "
              f"{pipeline_s:10.2f} {r['numpy_ratio']:15.4f} {wait.longest:14.2f} {same} "
              f"{wait.where}", flush=True)
    median = {key: statistics.median(r[key] for r in rows)
              for key in ("cli_s", "path_s", "path_ratio", "numpy_s", "pipeline_s", "numpy_ratio")}
    print(f"{'median':>5} {median['cli_s']:8.2f} {median['path_s']:8.2f} "
          f"{median['path_ratio']:9.4f} {median['numpy_s']:8.2f} {median['pipeline_s']:10.2f} "
          f"{median['numpy_ratio']:15.4f}")
    if args.json:
        print(json.dumps({"runs": rows, "median": median}))


if __name__ == "__main__":
    main()
