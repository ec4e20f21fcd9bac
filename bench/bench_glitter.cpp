// SPDX-License-Identifier: Apache-2.0
// Procedural glitter (Jakob et al. 2014): the cost of one counting query (a uv box of side 0.01 and
// a 1-degree cone, the paper's split rule for that query, with the binomial early stop) for N from
// 1e3 to 1e9 facets, against explicit enumeration of every facet (generate and test; up to 1e7).
// The hierarchy's cost should grow with log N; enumeration's grows with N.
#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/format/kinds/glitter_model.h>
#include <glintbake/format/numbers.h>
#include <glintbake/reference/glitter.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

namespace {

namespace glitter = glintbake::bake::glitter;
namespace format = glintbake::format;

using glintbake::kPi;
constexpr double kGamma = kPi / 180.0;

const glitter::GlitterModel& model(uint64_t n) {
  static std::unique_ptr<glitter::GlitterModel> cached;
  static uint64_t cached_n = 0;
  if (!cached || cached_n != n) {
    glitter::GlitterParams p;
    p.particles = n;
    p.alpha = 0.2;
    cached = std::make_unique<glitter::GlitterModel>(p);
    cached_n = n;
  }
  return *cached;
}

// Queries at a spread of positions and directions, so that no single lucky node decides the time.
format::GlitterUvRegion box(int i) {
  return format::GlitterUvRegion::box(0.13 + 0.071 * (i % 13), 0.29 + 0.053 * (i % 11), 0.01, 0.01);
}
format::GlitterDirRegion cone(int i) {
  const double sx = -0.2 + 0.03 * (i % 13), sy = -0.15 + 0.027 * (i % 11);
  return format::GlitterDirRegion::cone({sx, sy, std::sqrt(1 - sx * sx - sy * sy)}, kGamma);
}

void BM_GlitterCountHierarchy(benchmark::State& state) {
  const glitter::GlitterModel& m = model(uint64_t(std::pow(10.0, double(state.range(0)))));
  const format::GlitterTreeShape shape{1e-4, 2 * kPi * (1 - std::cos(kGamma))};
  int i = 0;
  uint64_t nodes = 0, queries = 0;
  for (auto _ : state) {
    format::GlitterCountStats stats;
    benchmark::DoNotOptimize(format::glitterCount(m.view(), shape, box(i), cone(i), {}, &stats));
    nodes += stats.nodes;
    ++queries;
    ++i;
  }
  state.counters["nodes"] = double(nodes) / double(queries);
  state.SetLabel("N = 1e" + std::to_string(state.range(0)));
}
BENCHMARK(BM_GlitterCountHierarchy)->DenseRange(3, 9)->Unit(benchmark::kMicrosecond);

void BM_GlitterCountEnumeration(benchmark::State& state) {
  const glitter::GlitterModel& m = model(uint64_t(std::pow(10.0, double(state.range(0)))));
  const format::GlitterTreeShape shape{1e-4, 2 * kPi * (1 - std::cos(kGamma))};
  int i = 0;
  for (auto _ : state) {
    // Brute force: every facet generated from the hierarchy, then tested.
    const auto facets = glintbake::reference::enumerateGlitterFacets(m.view(), shape);
    benchmark::DoNotOptimize(glintbake::reference::countGlitterFacets(facets, box(i), cone(i)));
    ++i;
  }
  state.SetLabel("N = 1e" + std::to_string(state.range(0)));
}
BENCHMARK(BM_GlitterCountEnumeration)->DenseRange(3, 7)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
