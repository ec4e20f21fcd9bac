#!/usr/bin/env bash
# The main job on the bundled example: builds the tools, then runs the example asset build
# (examples/Makefile) into examples/out/. Installs missing dependencies first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
make -C examples BIN="$PWD/build/bin"
