#!/bin/sh
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
for prog in "$build_dir"/bin/bench_*; do
  [ -x "$prog" ] || continue
  found=1
  echo "== $(basename "$prog")"
  "$prog" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
          --benchmark_filter="$filter" --benchmark_format=console 2>/dev/null |
    awk '/_median/ { sub(/_median/, "", $1); printf "  %-40s %12s %s\n", $1, $2, $3 }'
done
if [ "$found" = 0 ]; then
  echo "no bench_* programs in $build_dir/bin (configure with GLINTBAKE_BUILD_BENCH=ON)" >&2
  exit 1
fi
