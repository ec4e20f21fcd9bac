#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds the libFuzzer targets (clang, runtime-only configuration, in build-fuzz/) and runs each for
# SECONDS (default 20), seeded from valid files of every kind: the frozen containers of
# tests/format/ for the container and runtime targets, tests/fuzz/json/ for the JSON target and
# the tiny PNG/EXR/TIFF/JPEG/WebP maps of tests/fuzz/images/ for the ingest target (OIIO and TBB
# needed; it runs for INGEST_SECONDS, default 15, since each input is decoded through a temporary
# file).
# Corpora grow in build-fuzz/corpus/<target>/ across runs; a crash leaves its input in
# build-fuzz/artifacts/, prints it in base64 and fails the script. Prints "target: N execs" per
# target. The mutations follow a fixed seed (GLINTBAKE_FUZZ_SEED, default 1; 0 draws a new one), so
# that a run from the same corpus repeats the same inputs: a failure can be replayed, and a run
# here tells what a CI run of the same length will meet. Longer runs with other seeds are how new
# bugs are looked for.
#   scripts/fuzz.sh [SECONDS [INGEST_SECONDS]]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
ingest_seconds=${2:-15}
seed=${GLINTBAKE_FUZZ_SEED:-1}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [[ ! -f build-fuzz/CMakeCache.txt ]]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DGLINTBAKE_RUNTIME_ONLY=ON -DGLINTBAKE_BUILD_TESTS=OFF -DGLINTBAKE_BUILD_BENCH=OFF \
    -DGLINTBAKE_BUILD_FUZZ=ON >/dev/null
fi
targets=(fuzz_container fuzz_runtime fuzz_json)
# fuzz_ingest exists when the configuration found OpenImageIO and TBB.
[[ -d build-fuzz/tests/fuzz/CMakeFiles/fuzz_ingest.dir ]] && targets+=(fuzz_ingest)
cmake --build build-fuzz -j "$(nproc)" --target "${targets[@]}" >/dev/null

mkdir -p build-fuzz/artifacts
status=0
for target in "${targets[@]}"; do
  corpus=build-fuzz/corpus/$target
  mkdir -p "$corpus"
  run_seconds=$seconds
  extra=()
  runner=()
  if [[ $target == fuzz_json ]]; then
    cp tests/fuzz/json/* "$corpus"/
  elif [[ $target == fuzz_ingest ]]; then
    cp tests/fuzz/images/* "$corpus"/
    run_seconds=$ingest_seconds
    # OpenImageIO's PNG reader leaks its error strings when libpng longjmps out of a read callback
    # (not glintbake code; LSan's fast unwinder cannot tell those apart for a suppression): no leak
    # checks, neither per input nor at exit.
    extra=(-detect_leaks=0)
    runner=(env ASAN_OPTIONS=detect_leaks=0)
  else
    # The frozen files of every kind, and two assets with a flakes section and lobes (4 x 4 map,
    # R 8), which the frozen files lack (tests/fuzz/assets/: `ndfgen tests/fuzz/images/rgb8.png
    # --ndf-res 8` and `tensorpack --rank 4 --ndf-res 8 --block 4` on the same map).
    cp tests/format/*.gbk tests/fuzz/assets/*.gbk "$corpus"/
  fi
  log=build-fuzz/$target.log
  touch "build-fuzz/$target.started"
  if ! "${runner[@]}" build-fuzz/bin/$target "$corpus" -max_total_time="$run_seconds" -seed="$seed" -rss_limit_mb=2048 -timeout=10 \
       -max_len=262144 -artifact_prefix=build-fuzz/artifacts/ -print_final_stats=1 "${extra[@]}" >"$log" 2>&1; then
    echo "$target: FAILED (see $log and build-fuzz/artifacts/)" >&2
    grep -m1 '^INFO: Seed:' "$log" >&2 || true
    tail -30 "$log" >&2
    # The inputs that failed, in the log itself, so that a failure on another machine can be
    # replayed: `base64 -d > input; build-fuzz/bin/TARGET input`.
    for artifact in build-fuzz/artifacts/*; do
      [[ -f $artifact && $artifact -nt build-fuzz/$target.started ]] || continue
      echo "--- $artifact ($(stat -c %s "$artifact") bytes), base64:" >&2
      head -c 65536 "$artifact" | base64 -w 120 >&2
    done
    status=1
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  echo "$target: ${execs:-?} execs in ${run_seconds}s, corpus $(ls "$corpus" | wc -l) files"
done
exit $status
