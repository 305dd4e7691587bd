#!/usr/bin/env bash
# Installs what ULC needs on Debian 12 (run as root). Only Debian packages; nothing downloaded
# from elsewhere. Safe to run again. With --tests it also installs what only the tests use: Open3D
# and a virtual display for the Python example's window test (tests/python/test_example.py).
set -euo pipefail
packages=(g++ cmake ninja-build libeigen3-dev libtbb-dev libnanoflann-dev catch2 libstb-dev
  pkg-config libbz2-dev liblz4-dev libzstd-dev libsqlite3-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  pybind11-dev python3-dev python3-numpy python3-pytest)
if [ "${1:-}" = "--tests" ]; then
  packages+=(python3-open3d xvfb xauth libgl1-mesa-dri)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
