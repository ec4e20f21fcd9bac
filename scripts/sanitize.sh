#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Sanitizer builds (Debug, so the DCHECKs run too):
#   build-tsan/  runtime-only under TSan; runs the runtime's concurrency tests (threads hammering
#                eval, average, sample, pdf and mass on one shared asset).
#   build-asan/  the whole project under ASan+UBSan (libraries, tools, the Python module and tests;
#                no benchmarks), at -O1 with line tables only (-g1): faster
#                to run than -O0, and full debug information is not needed for symbolised reports.
#                Runs the whole CTest suite but the tests listed below, the CLI tests included, so
#                the tools themselves meet every damaged file and every option.
#   scripts/sanitize.sh
set -euo pipefail
cd "$(dirname "$0")/.."
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
jobs=${GLINTBAKE_JOBS:-$(nproc)}
# Leak checks everywhere. The one third-party leak suppression (tests/sanitizers/lsan.supp) can only
# match its library's frame with full malloc stacks (fast_unwind_on_malloc=0), which triple a
# tool's start-up under ASan; so the tests that meet that leak (the ingest of truncated PNGs) run
# apart with them, and everything else with the fast unwinder.
asan_fast=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
asan_full_stacks=${ASAN_OPTIONS:-detect_leaks=1:fast_unwind_on_malloc=0:abort_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}

# Both trees are configured on every run (seconds when nothing changed), so that a tree left by an
# earlier version of this script takes today's settings; the generator is kept from its first run.
tsan_generator=() asan_generator=()
[[ -f build-tsan/CMakeCache.txt ]] || tsan_generator=("${generator[@]}")
[[ -f build-asan/CMakeCache.txt ]] || asan_generator=("${generator[@]}")
cmake -S . -B build-tsan "${tsan_generator[@]}" "${launcher[@]}" -DCMAKE_BUILD_TYPE=Debug -DGLINTBAKE_SANITIZE=thread \
  -DGLINTBAKE_RUNTIME_ONLY=ON -DGLINTBAKE_BUILD_BENCH=OFF -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build-tsan -j "$jobs" --target test_runtime_ndf >/dev/null
ctest --test-dir build-tsan --output-on-failure -R Concurrent

# A unity build (several sources of a target compiled as one): the headers are parsed and
# instrumented once per batch instead of once per source (on two cores about 520 s instead of 900 s).
cmake -S . -B build-asan "${asan_generator[@]}" "${launcher[@]}" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_UNITY_BUILD=ON \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DCMAKE_C_FLAGS_DEBUG="-O1 -g1" \
  -DGLINTBAKE_SANITIZE=address,undefined -DGLINTBAKE_BUILD_BENCH=OFF -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build-asan -j "$jobs" >/dev/null
# Not run under ASan (all of them run in the normal build):
#  - install.*: the consumer projects are built without the sanitizer runtime, so they cannot link
#    the instrumented libraries;
#  - cli.report: the HTML report renders every map with the reference and measures render times
#    and speedups (its point is performance); its tools run in the CLI tests here;
#  - the statistical tests: millions of samples each (chi-square, Monte Carlo, 500-sweep CP
#    references; the tiny examples' sampler-against-eval tests are chi-square tests too), minutes
#    apiece under ASan; their code paths also run in the quick tests here;
#  - LobeNdf.InnerTilesFromTheExactFlakesCountOnce: five maps' whole windows compared tile by tile
#    with the exact flakes (84 s under ASan); the lobe tests here walk the same windows;
#  - the CLI tests that replay whole bakes and renders of valid inputs (shard, tiny examples,
#    renders, glitter, Wang tiles, LTC fit, mapgen, manifests, the reference tool): about 640 s
#    of CPU under ASan (half the stage's test time) for code the unit tests here already run. The
#    tools still meet every damaged file, bad option and malformed input under ASan: the contract,
#    hardening and usability tests run, as do ndfgen, tensorpack, glintquery and glintinfo.
excluded='^install[.]|^cli[.]report$|SamplesFollowTheirPdf|ClusteredLevelsStayClose|MillionSample|ChiSquare|MonteCarlo|TinyExample[.]SamplingMatchesEval|InnerTilesFromTheExactFlakesCountOnce|^LtcTable[.]|FiveHundredPlainSweeps|RecoversExactLowRank'
excluded+='|^cli[.](shard|tinyexample|render|render_tensor|glitter|glintbake|glintref|mapgen|ltcfit|wangtile)$'
full_stacks='^Ingest[.]'
ASAN_OPTIONS=$asan_fast ctest --test-dir build-asan --output-on-failure -j "$jobs" --timeout 1800 \
  -E "$excluded|$full_stacks"
ASAN_OPTIONS=$asan_full_stacks ctest --test-dir build-asan --output-on-failure -j "$jobs" --timeout 1800 \
  -E "$excluded" -R "$full_stacks"
