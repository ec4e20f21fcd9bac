#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The main job on the bundled example: builds the tools, runs the example asset build
# (examples/Makefile) into examples/out/, then renders the report (out/report/index.html).
# Installs missing dependencies first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
make -C examples BIN="$PWD/build/bin"
scripts/make-report.py --bin "$PWD/build/bin" --maps examples/out/maps --out out/report
