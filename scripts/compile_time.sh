#!/usr/bin/env bash
# Compile time of a user's file that calls ulc::calibrate_pair on its own point struct
# (bench/compile_time/user_calibrate.cpp), at -O2 on one core, with the compiler's peak memory:
#   1. through pipeline/calibrate.hpp, the pipeline compiled once elsewhere (ulc::calibrate);
#   2. the pipeline itself, compiled once (pipeline/implementation.hpp): what ulc::calibrate
#      costs, paid once per build;
#   3. the baseline of the same run: calibrate_pair_in_place, every stage compiled for the
#      user's type in the user's file (how every such file compiled before ulc::calibrate).
# Usage: bash scripts/compile_time.sh [--skip-baseline]. Needs g++ and Debian's `time`.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v /usr/bin/time >/dev/null || { apt-get install -y -qq time >/dev/null; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
flags=(-std=c++17 -O2 -Iinclude -I/usr/include/eigen3 -c)
measure() {  # label, then the compiler arguments
  local label=$1
  shift
  /usr/bin/time -f "%e %M" -o "$out/time" taskset -c 0 g++ "${flags[@]}" "$@"
  read -r seconds kib <"$out/time"
  printf '%-44s %8.1f s %8.0f MiB\n' "$label" "$seconds" "$((kib / 1024))"
}
printf '%-44s %10s %12s\n' "file" "wall" "peak memory"
measure "user file via pipeline/calibrate.hpp" bench/compile_time/user_calibrate.cpp -o "$out/a.o"
printf '#include "pipeline/implementation.hpp"\n' >"$out/impl.cpp"
measure "the pipeline, once (ulc::calibrate)" "$out/impl.cpp" -o "$out/b.o"
if [ "${1:-}" != "--skip-baseline" ]; then
  measure "baseline: user file, stages in place" -DULC_IN_PLACE \
    bench/compile_time/user_calibrate.cpp -o "$out/c.o"
fi
