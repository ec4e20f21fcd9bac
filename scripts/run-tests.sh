#!/usr/bin/env bash
# Builds everything and runs the whole test suite (CTest). Installs missing dependencies first.
# First a runtime-only configuration (container library + runtime-lite, no OpenImageIO, Ceres,
# TBB or Eigen) is built and tested, as a renderer would build it; then the full project.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --browser

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
cmake -S . -B build-runtime-only "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DGLINTBAKE_RUNTIME_ONLY=ON \
  -DGLINTBAKE_BUILD_BENCH=OFF -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build-runtime-only -j "$(nproc)" >/dev/null
ctest --test-dir build-runtime-only --output-on-failure -j "$(nproc)"

scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 900
