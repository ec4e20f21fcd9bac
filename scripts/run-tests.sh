#!/usr/bin/env bash
# Builds everything and runs the whole test suite (CTest). Installs missing dependencies first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 900
