#!/usr/bin/env bash
# The README's main job: installs the dependencies, builds the `ulc` command and the examples,
# and runs the most complete program ULC has today (see README, "What works today").
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
jobs=${ULC_JOBS:-$(nproc)}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DULC_BUILD_TESTS=OFF -DULC_BUILD_BENCH=OFF \
  -DULC_BUILD_APPS=ON -DULC_BUILD_EXAMPLES=ON
cmake --build build -j "$jobs" --target ulc_app example_custom_point_type example_calibrate_own_points
ulc=./build/apps/ulc/ulc
./build/examples/example_custom_point_type
# The whole calibration on a user's own point struct, checked against the simulator's truth.
./build/examples/example_calibrate_own_points
out=${ULC_OUT:-/tmp/ulc_demo}
$ulc simulate --scenario 64-horizon --seconds 30 --seed 1 --out "$out/64-horizon" \
  --preview "$out/64-horizon_preview.png"
$ulc inspect "$out/64-horizon/lidar64"
$ulc inspect "$out/64-horizon/horizon"
# Calibrate with no initial guess, every stage (TERRA, JEEP, odometry, HOTS with the time
# synchronisation), and compare with the ground truth.
$ulc calibrate --base "$out/64-horizon/lidar64" --target "$out/64-horizon/horizon" \
  --output "$out/64-horizon/result.json" --report "$out/64-horizon/report.png" --quiet
$ulc evaluate --result "$out/64-horizon/result.json" \
  --ground-truth "$out/64-horizon/ground_truth.json"
sample=../shared/data/real/croon_0003
if [ -d "$sample" ]; then
  # The real single-frame rig: TERRA, then JEEP's registration on the single frames (HOTS
  # needs motion and skips itself), checked against the shipped result.
  $ulc calibrate --base "$sample/top.pcd" --target "$sample/left.pcd" --target "$sample/right.pcd" \
    --output "$out/croon_0003.json" --quiet
  $ulc evaluate --result "$out/croon_0003.json" --ground-truth "$sample/ground_truth.json"
fi
