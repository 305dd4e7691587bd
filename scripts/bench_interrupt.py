#!/usr/bin/env python3
"""Latency from Ctrl-C (SIGINT) to the exit of `ulc calibrate`, and what it leaves behind.

Simulates a drive once, then runs `ulc calibrate` on it REPEATS times; each run gets SIGINT
after WAIT seconds (while it is still calibrating) and the time from the signal to the process's
exit is measured. Each run must exit 130 and leave neither the result file, the merged cloud,
the report nor any temporary (".ulc-tmp-") in the output folder. Prints one line per run and
the median (docs/BENCHMARKS.md, "Safe output: Ctrl-C").

usage: scripts/bench_interrupt.py ULC [--repeats 5] [--wait 3] [--out /tmp/ulc_bench_interrupt]
"""
import argparse
import os
import pathlib
import shutil
import signal
import statistics
import subprocess
import sys
import time


def simulate(ulc, out):
    drive = out / "drive"
    shutil.rmtree(drive, ignore_errors=True)
    subprocess.run([ulc, "simulate", "--quiet", "--scenario", "64-32", "--seconds", "6",
                    "--seed", "1", "--out", str(drive)], check=True)
    return drive


def one_run(ulc, drive, results, wait):
    shutil.rmtree(results, ignore_errors=True)
    results.mkdir(parents=True)
    outputs = [results / "result.json", results / "merged.pcd", results / "report.png"]
    command = [ulc, "calibrate", "--quiet", "--base", str(drive / "lidar64"), "--target",
               str(drive / "lidar32"), "--output", str(outputs[0]), "--merged-cloud",
               str(outputs[1]), "--report", str(outputs[2])]
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    time.sleep(wait)
    if proc.poll() is not None:
        sys.exit(f"ulc calibrate finished before the signal (exit {proc.returncode}): "
                 "raise --wait's drive length")
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    proc.wait()
    latency = time.monotonic() - sent
    left = [p.name for p in results.iterdir()]
    return latency, proc.returncode, left, proc.stderr.read().decode().strip()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("ulc")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--wait", type=float, default=3.0)
    parser.add_argument("--out", default="/tmp/ulc_bench_interrupt")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    drive = simulate(os.path.abspath(args.ulc), out)
    latencies = []
    for i in range(args.repeats):
        latency, code, left, message = one_run(os.path.abspath(args.ulc), drive,
                                               out / "results", args.wait)
        latencies.append(latency)
        print(f"run {i + 1}: SIGINT -> exit {latency * 1e3:8.2f} ms, exit code {code}, "
              f"files left: {left or 'none'}; stderr: {message}")
        if code != 130 or left:
            sys.exit("FAILED: expected exit code 130 and no file left")
    print(f"median over {args.repeats} runs: {statistics.median(latencies) * 1e3:.2f} ms "
          f"(max {max(latencies) * 1e3:.2f} ms)")
    shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    main()
