#!/usr/bin/env bash
# The README's main job: installs the dependencies, builds the `ulc` command and the examples,
# and runs the most complete program ULC has today (see README, "What works today").
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
jobs=${ULC_JOBS:-$(nproc)}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DULC_BUILD_TESTS=OFF -DULC_BUILD_BENCH=OFF
cmake --build build -j "$jobs" --target ulc_app example_custom_point_type
./build/examples/example_custom_point_type
sample=../shared/data/real/croon_0003
if [ -d "$sample" ]; then
  ./build/apps/ulc/ulc inspect "$sample/top.pcd"
  ./build/apps/ulc/ulc inspect "$sample/left.pcd"
fi
