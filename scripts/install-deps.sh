#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the Debian packages glintbake needs to build, test and run its examples, if any are
# missing. As root it runs apt-get; otherwise it prints the exact command and exits non-zero.
#   scripts/install-deps.sh [--browser]   (--browser adds chromium for the report's browser test)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config make python3 python3-jsonschema
  libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev libeigen3-dev libceres-dev libtbb-dev
  libcli11-dev nlohmann-json3-dev libzstd-dev libxxhash-dev
  python3-dev pybind11-dev python3-numpy python3-pytest  # the Python module and its tests
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-dev  # libFuzzer targets (scripts/fuzz.sh): the fuzzer runtime is not a dependency of clang
  slurm-wlm slurmctld slurmd slurm-client munge  # the one-node Slurm cluster of tests/slurm
  time  # /usr/bin/time -v: per-task wall and peak memory in scripts/slurm-scale.py
)
if [[ "${1:-}" == "--browser" ]]; then
  packages+=(chromium)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

if [[ $(id -u) -eq 0 ]]; then
  echo "installing: ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "glintbake needs these Debian packages; install them with:" >&2
  echo "  sudo apt-get install -y ${missing[*]}" >&2
  exit 1
fi
