#!/usr/bin/env bash
# The README's main job: installs the dependencies, builds the `ulc` command and the examples,
# and runs the most complete program ULC has today (see README, "What works today").
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
jobs=${ULC_JOBS:-$(nproc)}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DULC_BUILD_TESTS=OFF -DULC_BUILD_BENCH=OFF
cmake --build build -j "$jobs" --target ulc_app example_custom_point_type
ulc=./build/apps/ulc/ulc
./build/examples/example_custom_point_type
out=${ULC_OUT:-/tmp/ulc_demo}
$ulc simulate --scenario 64-32 --seconds 3 --seed 1 --out "$out/64-32" --preview "$out/64-32.png"
$ulc inspect "$out/64-32/lidar64"
$ulc inspect "$out/64-32/lidar32"
# Calibrate with no initial guess (TERRA, then JEEP) and compare with the ground truth. HOTS
# (the default third stage) is left out here: on a 3 s drive it takes ~25 s and does not improve
# on JEEP yet (docs/BENCHMARKS.md, bench_hots).
$ulc calibrate --base "$out/64-32/lidar64" --target "$out/64-32/lidar32" --stages terra,jeep \
  --output "$out/64-32/result.json" --quiet
$ulc evaluate --result "$out/64-32/result.json" --ground-truth "$out/64-32/ground_truth.json"
sample=../shared/data/real/croon_0003
if [ -d "$sample" ]; then
  # The real single-frame rig: rotations only (TERRA), checked against the shipped ones.
  $ulc calibrate --base "$sample/top.pcd" --target "$sample/left.pcd" --target "$sample/right.pcd" \
    --stages terra --output "$out/croon_0003.json" --quiet
  $ulc evaluate --result "$out/croon_0003.json" --ground-truth "$sample/ground_truth.json" || true
fi
