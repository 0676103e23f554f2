#!/usr/bin/env bash
# Installs every Debian 12 package fleetmap needs to build, test and benchmark.
# Idempotent: when everything is present it only checks and returns in about a second.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libopencv-dev libompl-dev liboctomap-dev libpng-dev
  libboost-serialization-dev libboost-filesystem-dev libboost-system-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libceres-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libfmt-dev libexpat1-dev
  pybind11-dev python3-dev python3-numpy
  slurm-wlm
  chromium  # the tests that open fleetmap's HTML pages in a real, headless browser
)
# `--robustness` adds clang and its libFuzzer runtime, for the fuzzing stage of .ci/run.
[[ "${1:-}" == "--robustness" ]] && packages+=(clang libclang-rt-14-dev)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" </dev/null
echo "install-deps: done"
