#!/usr/bin/env bash
# Installs the dependencies, builds the library's tests and the ulc command in Release with
# assertions on, and runs every test. The benchmarks and the examples are left out (each file
# including ulc/calibrate.hpp takes ~3-4 minutes on 2 cores; each test folder is compiled as one
# translation unit for the same reason, tests/CMakeLists.txt): the README's main job
# (scripts/run.sh) builds and runs the self-checking examples, and
# `cmake -S . -B build -DULC_BUILD_BENCH=ON && cmake --build build` builds the benchmarks
# (docs/BENCHMARKS.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
jobs=${ULC_JOBS:-$(nproc)}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DULC_ASSERTIONS=ON -DULC_BUILD_TESTS=ON \
  -DULC_BUILD_APPS=ON -DULC_BUILD_BENCH=OFF -DULC_BUILD_EXAMPLES=OFF
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"
