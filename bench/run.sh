#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# Runs every bench_* program of a build with repetitions and prints the median of each benchmark.
#
#   bench/run.sh [BUILD_DIR] [REPETITIONS] [FILTER]
#
# BUILD_DIR defaults to ./build, REPETITIONS to 5, FILTER (a --benchmark_filter regex) to all.
set -eu
build_dir=${1:-build}
reps=${2:-5}
filter=${3:-.}
found=0
failed=0
out=$(mktemp)
err=$(mktemp)
trap 'rm -f "$out" "$err"' EXIT
for prog in "$build_dir"/bin/bench_*; do
  [ -x "$prog" ] || continue
  found=1
  echo "== $(basename "$prog")"
  # A benchmark that fails (non-zero exit, or a SkipWithError reported as error_occurred) fails the
  # whole run, with its stderr shown.
  if "$prog" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
     --benchmark_filter="$filter" --benchmark_format=console >"$out" 2>"$err" &&
     ! grep -q "ERROR OCCURRED" "$out"; then
    awk '/_median/ { sub(/_median/, "", $1); printf "  %-40s %12s %s\n", $1, $2, $3 }' "$out"
  else
    echo "$(basename "$prog"): FAILED" >&2
    cat "$err" >&2
    grep "ERROR OCCURRED" "$out" >&2 || true
    failed=1
  fi
done
if [ "$found" = 0 ]; then
  echo "no bench_* programs in $build_dir/bin (configure with GLINTBAKE_BUILD_BENCH=ON)" >&2
  exit 1
fi
exit "$failed"
