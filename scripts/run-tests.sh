#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds everything and runs the whole test suite (CTest). Installs missing dependencies first.
#  1. a runtime-only configuration (container library + runtime-lite, no OpenImageIO, Ceres, TBB
#     or Eigen), as shared libraries, built and tested as a renderer would build it;
#  2. the full project, Release, with warnings as errors (GLINTBAKE_WERROR), every test;
#  3. sanitizers (scripts/sanitize.sh): the whole suite (CLI tests included; not the install,
#     report and statistical tests) under ASan+UBSan in a Debug build of the whole project, the
#     runtime's concurrency test under TSan;
#  4. a short run of every libFuzzer target (scripts/fuzz.sh, clang), seeded from valid files of
#     every kind.
# Each stage's wall time is printed at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --browser

timings=()
stage() {
  local name=$1 start=$SECONDS
  shift
  echo "=== $name"
  "$@"
  timings+=("$name: $((SECONDS - start)) s")
}

runtime_only() {
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  # Shared libraries here (the full build below is static), so that the install consumers, the C
  # program linked with pkg-config and the Python module are also tested against a shared runtime.
  cmake -S . -B build-runtime-only "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DGLINTBAKE_RUNTIME_ONLY=ON \
    -DBUILD_SHARED_LIBS=ON -DGLINTBAKE_BUILD_BENCH=OFF -DGLINTBAKE_WERROR=ON -DPython3_EXECUTABLE=/usr/bin/python3 \
    >/dev/null
  cmake --build build-runtime-only -j "$(nproc)" >/dev/null
  ctest --test-dir build-runtime-only --output-on-failure -j "$(nproc)"
}

full() {
  scripts/build.sh -DGLINTBAKE_WERROR=ON
  ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 900
}

stage "runtime-only" runtime_only
stage "full build and tests" full
stage "sanitizers" scripts/sanitize.sh
stage "fuzz" scripts/fuzz.sh "${GLINTBAKE_FUZZ_SECONDS:-20}"
printf '%s\n' "${timings[@]}"
