#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with Debian's clang and runs each for N seconds.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     default 60 s, every target; 600 for the long runs
#
# Each target runs on a scratch copy of tests/fuzz/corpus/<target>/ (the committed seeds are
# never written to). Per target it prints the executions, the coverage (cov: edges, ft: features
# from libFuzzer's final line) and whether it found anything. A finding (crash, sanitizer report,
# leak, timeout, out of memory) is kept under build-fuzz/findings/<target>/ and the script exits
# 1 naming the reproducer; rerun one with build-fuzz/<target> <reproducer>.
# Environment: FUZZ_BUILD_JOBS (default 1) compile jobs.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

seconds=${1:-60}
shift || true
all_targets=(fuzz_pcd fuzz_ply fuzz_kitti fuzz_timestamps fuzz_json fuzz_ros1_bag fuzz_mcap
  fuzz_rosbag2_sqlite fuzz_cloud_message)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
if ! [[ $seconds =~ ^[0-9]+$ ]] || [ "$seconds" -eq 0 ]; then
  echo "usage: scripts/fuzz.sh [SECONDS] [TARGET...] (targets: ${all_targets[*]})" >&2
  exit 2
fi

# Longest input per target: large enough for the seeds and their growth, small enough to keep
# the executions fast (text formats need less room than recordings).
max_len_of() {
  case $1 in
    fuzz_timestamps) echo 8192 ;;
    fuzz_json | fuzz_cloud_message) echo 16384 ;;
    *) echo 65536 ;;
  esac
}

install_missing() {
  local packages=(clang libclang-rt-14-dev cmake ninja-build pkg-config libeigen3-dev libtbb-dev
    libnanoflann-dev libbz2-dev liblz4-dev libzstd-dev libsqlite3-dev libyaml-cpp-dev
    nlohmann-json3-dev)
  local missing=() p
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
      missing+=("$p")
  done
  [ ${#missing[@]} -gt 0 ] || return 0
  echo "installing: ${missing[*]}" >&2
  local sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

build() {
  cmake -S tests/fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
  cmake --build build-fuzz -j "${FUZZ_BUILD_JOBS:-1}" --target "${targets[@]}"
}

# The last value of `key` (cov:, ft:, corp:) on libFuzzer's status lines.
status_value() {
  grep -E "^#[0-9]+" "$2" | grep -oE "$1 [0-9]+(/[0-9]+[a-zA-Z]*)?" | tail -n 1 |
    awk '{print $2}'
}

final_stat() {
  grep -E "^stat::$1:" "$2" | awk '{print $2}' | tail -n 1
}

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

install_missing
build

findings=0
summary=()
for t in "${targets[@]}"; do
  corpus="$scratch/corpus/$t"
  artifacts="$root/build-fuzz/findings/$t"
  log="$root/build-fuzz/logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")" "$scratch/files"
  cp -r "tests/fuzz/corpus/$t/." "$corpus/"
  echo "== $t: ${seconds} s" >&2
  set +e
  ULC_FUZZ_SCRATCH="$scratch/files" ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0} \
    UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    "build-fuzz/$t" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=2048 \
    -timeout=10 -max_len="$(max_len_of "$t")" -artifact_prefix="$artifacts/" "$corpus" \
    >"$log" 2>&1
  rc=$?
  set -e
  execs=$(final_stat number_of_executed_units "$log")
  rate=$(final_stat average_exec_per_sec "$log")
  cov=$(status_value "cov:" "$log")
  ft=$(status_value "ft:" "$log")
  # Slow units are not findings (the timeout is); every other artifact is a reproducer.
  reproducers=$(grep -oE "Test unit written to [^ ]+" "$log" | awk '{print $NF}' |
    grep -v "/slow-unit-" | sort -u | tr '\n' ' ' || true)
  if [ "$rc" -eq 0 ] && [ -z "$reproducers" ]; then
    result="no finding"
  else
    findings=$((findings + 1))
    # The most specific line: a UBSan report or a broken property, else the sanitizer's verdict.
    kind=$(grep -m 1 -E "runtime error|property violated" "$log" || true)
    [ -n "$kind" ] ||
      kind=$(grep -m 1 -oE "ERROR: [A-Za-z]+: [a-zA-Z-]+" "$log" | sed 's/^ERROR: //' || true)
    [ -n "$kind" ] || kind="exit $rc"
    result="FINDING ($kind): ${reproducers:-see $log}"
  fi
  line=$(printf '%-20s execs %10s (%s/s)  cov %6s  ft %6s  %s' "$t" "${execs:-?}" "${rate:-?}" \
    "${cov:-?}" "${ft:-?}" "$result")
  echo "$line" >&2
  summary+=("$line")
done

echo
echo "fuzzing, ${seconds} s per target (logs in build-fuzz/logs/):"
printf '%s\n' "${summary[@]}"
if [ "$findings" -gt 0 ]; then
  echo "$findings target(s) found something; reproduce with build-fuzz/<target> <reproducer>" >&2
  exit 1
fi
