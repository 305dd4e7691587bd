#!/usr/bin/env bash
# Installs the dependencies, builds the library's tests, examples and the ulc command in Release
# with assertions on, and runs every test. The benchmarks are left out (they are programs, not
# tests, and compiling them took 5 of CI's 30 minutes on 2 cores): build them with
# `cmake -S . -B build -DULC_BUILD_BENCH=ON && cmake --build build` (docs/BENCHMARKS.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
jobs=${ULC_JOBS:-$(nproc)}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DULC_ASSERTIONS=ON -DULC_BUILD_BENCH=OFF
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"
