#!/usr/bin/env bash
# Installs the dependencies, builds the library's tests and the ulc command in Release with
# assertions on, and runs every test; then fuzzes every parser briefly, and builds the parsers'
# tests with AddressSanitizer and UndefinedBehaviorSanitizer and runs them. The benchmarks and the examples are left out (several
# benchmarks compile the stages for their own types, minutes each; each test folder is compiled as
# one translation unit for the same reason, tests/CMakeLists.txt): the README's main job
# (scripts/run.sh) builds and runs the self-checking examples, and
# `cmake -S . -B build -DULC_BUILD_BENCH=ON && cmake --build build` builds the benchmarks
# (docs/BENCHMARKS.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh --tests
jobs=${ULC_JOBS:-$(nproc)}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DULC_ASSERTIONS=ON -DULC_BUILD_TESTS=ON \
  -DULC_BUILD_APPS=ON -DULC_BUILD_PYTHON=ON -DULC_BUILD_BENCH=OFF -DULC_BUILD_EXAMPLES=OFF
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

# Every parser's libFuzzer target (tests/fuzz, Debian's clang) for a short run on its seeds and
# the inputs that once found bugs: scripts/fuzz.sh 600 is the long run (docs/BENCHMARKS.md).
FUZZ_BUILD_JOBS=$jobs bash scripts/fuzz.sh 10

# The parsers' and containers' tests again under AddressSanitizer and UndefinedBehaviorSanitizer,
# in their own build folder: every reader of files and recordings, of result files and ground
# truth (tests/json), the point traits, kd-tree, voxels and parallel reduce. The algorithm
# folders (lie, registration, terra, sim, jeep, hots, calibrate) and the app are left out for
# CI's time: each takes minutes to compile under the sanitizers (add their names to `sanitized`
# to run them).
sanitized=(bag_messages core io json mcap ros1_bag rosbag2 spatial)
cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DULC_ASSERTIONS=ON \
  -DULC_SANITIZE=ON -DULC_BUILD_TESTS=ON -DULC_BUILD_APPS=OFF -DULC_BUILD_BENCH=OFF \
  -DULC_BUILD_EXAMPLES=OFF
cmake --build build-sanitize -j "$jobs" --target "${sanitized[@]/#/test_}"
labels=$(IFS='|'; echo "^(${sanitized[*]})\$")
ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -L "$labels"
