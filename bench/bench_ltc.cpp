// SPDX-License-Identifier: Apache-2.0
// LTC benchmarks: the full 64 x 64 GGX table fit at the default (refined) settings and with the
// published settings, each reporting its fit error on the `ltcfit eval` measure (128^2 samples per
// strategy), and the runtime cost of one lookup + rectangle integral.
#include <glintbake/bake/ltc/table.h>
#include <glintbake/runtime/ltc.h>

#include <benchmark/benchmark.h>

namespace {

using namespace glintbake::bake::ltc;

void fitAndEvaluate(benchmark::State& state, FitMethod method) {
  TableFitOptions options;
  options.method = method;
  PublishedTable table;
  for (auto _ : state) {
    FittedTable fitted = fitTable(options).value();
    table = packPublished(fitted);
    benchmark::DoNotOptimize(table.ltc1.data());
  }
  const TableError error = evaluateTable(table, BrdfKind::kGgx, 128).value();
  state.counters["mean_relative_l1"] = error.mean_relative_l1;
  state.counters["max_relative_l1"] = error.max_relative_l1;
  state.counters["mean_log10_objective"] = error.mean_log10_objective;
}

void BM_GgxTable64Refined(benchmark::State& state) { fitAndEvaluate(state, FitMethod::kRefined); }
void BM_GgxTable64Published(benchmark::State& state) { fitAndEvaluate(state, FitMethod::kPublished); }
BENCHMARK(BM_GgxTable64Refined)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_GgxTable64Published)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_RuntimeLookupAndRectangle(benchmark::State& state) {
  TableFitOptions options;
  options.size = 8;
  options.samples = 8;
  const PublishedTable published = packPublished(fitTable(options).value());
  glintbake::runtime::LtcTable table;
  table.fromArrays(published.size, published.ltc1.data(), published.ltc2.data());
  const float quad[4][3] = {{-0.5f, -1.0f, 1.0f}, {1.5f, -1.0f, 1.0f}, {1.5f, 0.5f, 1.0f}, {-0.5f, 0.5f, 1.0f}};
  float roughness = 0.1f;
  for (auto _ : state) {
    glintbake::runtime::LtcCoefficients c;
    table.lookup(roughness, 0.7f, &c);
    benchmark::DoNotOptimize(c.norm * glintbake::runtime::ltcIntegratePolygon(c, quad, 4, false));
    roughness = roughness > 0.9f ? 0.1f : roughness + 0.01f;
  }
}
BENCHMARK(BM_RuntimeLookupAndRectangle);

}  // namespace

BENCHMARK_MAIN();
