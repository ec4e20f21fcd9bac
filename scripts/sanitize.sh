#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Sanitizer builds (Debug, so the DCHECKs run too):
#   build-asan/  the project under ASan+UBSan: the GoogleTest programs and their libraries (the
#                whole project with --cli); runs the unit tests (and the CLI tests with --cli),
#                every finding failing its test;
#   build-tsan/  runtime-only under TSan; runs the runtime's concurrency tests (threads hammering
#                eval, average, sample, pdf and mass on one shared asset).
#   scripts/sanitize.sh [--cli]
set -euo pipefail
cd "$(dirname "$0")/.."
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
jobs=${GLINTBAKE_JOBS:-$(nproc)}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:fast_unwind_on_malloc=0:abort_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}

if [[ ! -f build-tsan/CMakeCache.txt ]]; then
  cmake -S . -B build-tsan "${generator[@]}" "${launcher[@]}" -DCMAKE_BUILD_TYPE=Debug -DGLINTBAKE_SANITIZE=thread \
    -DGLINTBAKE_RUNTIME_ONLY=ON -DGLINTBAKE_BUILD_BENCH=OFF -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
fi
cmake --build build-tsan -j "$jobs" --target test_runtime_ndf >/dev/null
ctest --test-dir build-tsan --output-on-failure -R Concurrent

if [[ ! -f build-asan/CMakeCache.txt ]]; then
  cmake -S . -B build-asan "${generator[@]}" "${launcher[@]}" -DCMAKE_BUILD_TYPE=Debug \
    -DGLINTBAKE_SANITIZE=address,undefined -DGLINTBAKE_BUILD_BENCH=OFF -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
fi
if [[ "${1:-}" == "--cli" ]]; then
  cmake --build build-asan -j "$jobs" >/dev/null
else
  cmake --build build-asan -j "$jobs" --target glintbake_unit_tests >/dev/null  # no tools, no benchmarks
fi
if [[ "${1:-}" == "--cli" ]]; then
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -E '^install[.]' --timeout 1800
else
  # The install test builds a consumer project without the sanitizer runtime, and the statistical
  # tests (millions of samples, 30-450 s each under ASan at -O0; their code paths also run in the
  # quick tests here) stay in the normal build: that keeps this stage near 7 minutes.
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE cli --timeout 900 \
    -E '^install[.]|SamplesFollowTheirPdf|ClusteredLevelsStayClose|MillionSample|ChiSquare|MonteCarlo|^LtcTable[.]|FiveHundredPlainSweeps|RecoversExactLowRank'
fi
