// SPDX-License-Identifier: Apache-2.0
// The reference evaluator's cost: bin-averaged NDF images (R = 128) at footprint sigmas of 2, 8 and
// 32 texels, and point evaluations of D(s) at sigma 32, on a 256^2 Beckmann map (alpha 0.3) built
// in the benchmark. Images run on one thread (a TBB arena of 1) so that the figures do not depend
// on what else the machine runs; the cost scales with the flakes in the footprint, about
// pi (6 sqrt(sigma^2 + sigma_h^2))^2.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/reference/flakes.h>
#include <glintbake/reference/pndf.h>

#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cstddef>
#include <vector>

namespace {

namespace bake = glintbake::bake;
namespace reference = glintbake::reference;

constexpr int kNdfRes = 128;

const reference::FlakeSet& benchFlakes() {
  static const reference::FlakeSet flakes = [] {
    bake::MapParams params;
    params.size = 256;
    params.seed = 42;
    params.alpha = 0.3;
    return reference::buildFlakes(bake::generateMap(bake::MapKind::kBeckmann, params), 1);
  }();
  return flakes;
}

void BM_ReferenceBinAveragedImage(benchmark::State& state) {
  const reference::FlakeSet& flakes = benchFlakes();
  const reference::Footprint fp{100.3, 57.8, double(state.range(0))};
  tbb::task_arena one_thread(1);
  for (auto _ : state) {
    one_thread.execute([&] {
      std::vector<double> image = reference::binAveragedImage(flakes, fp, reference::kDefaultSigmaR, kNdfRes);
      benchmark::DoNotOptimize(image.data());
    });
  }
  state.counters["lobes"] = double(reference::footprintLobes(flakes, fp, reference::kDefaultSigmaR).size());
}
BENCHMARK(BM_ReferenceBinAveragedImage)->Arg(2)->Arg(8)->Unit(benchmark::kMillisecond);
// A sigma-32 image takes seconds: one iteration per repetition.
BENCHMARK(BM_ReferenceBinAveragedImage)->Arg(32)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_ReferenceEvalPndf(benchmark::State& state) {
  const reference::FlakeSet& flakes = benchFlakes();
  const reference::Footprint fp{100.3, 57.8, double(state.range(0))};
  // Query points on a small grid around the NDF's bulk, cycled in a fixed order.
  std::vector<double> points;
  for (int j = -3; j <= 3; ++j) {
    for (int i = -3; i <= 3; ++i) {
      points.push_back(0.04 * i);
      points.push_back(0.04 * j);
    }
  }
  size_t next = 0;
  for (auto _ : state) {
    const double value = reference::evalPndf(flakes, fp, points[next], points[next + 1], reference::kDefaultSigmaR);
    benchmark::DoNotOptimize(value);
    next = (next + 2) % points.size();
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_ReferenceEvalPndf)->Arg(32)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
