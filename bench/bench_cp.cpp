// SPDX-License-Identifier: Apache-2.0
// CP tensor compression and its runtime queries: one sweep against the GEMM-bound floor, full
// decompositions per method (time and error), and blended point / range / sample latency.
// Targets: sweep on 32x32x2048 rank 16 within 1.3x of the floor
// (about 2.0-2.5 ms); default method at most 1/5 of the time of 500 plain sweeps at an error within
// 1%; queries on an 8-way blend at rank 16: point 150 ns, range 300 ns, sample 1.5 us.
#include <glintbake/bake/tensor/cp_decomposition.h>
#include <glintbake/bake/tensor/cp_profile.h>
#include <glintbake/bake/tensor/prefix_sums.h>
#include <glintbake/runtime/cp_block.h>

#include <glintbake/bake/tensor/synthetic_groups.h>

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <random>

namespace {

using namespace glintbake;
using bake::tensor::CpMethod;
using bake::tensor::CpOptions;
using bake::tensor::GroupTensor;

const GroupTensor& tensorOf(int blocks) {
  static std::map<int, GroupTensor> cache;
  auto it = cache.find(blocks);
  if (it == cache.end()) it = cache.emplace(blocks, bake::tensor::makeNdfLikeGroup(32, blocks, 2026)).first;
  return it->second;
}

void BM_CpSweep(benchmark::State& state) {
  const GroupTensor& t = tensorOf(static_cast<int>(state.range(0)));
  const int rank = static_cast<int>(state.range(1));
  bake::tensor::CpSweepTiming timing;
  for (auto _ : state) {
    timing = bake::tensor::timeCpSweeps(t, rank, 5);
    state.SetIterationTime(timing.sweep_seconds);
  }
  state.counters["floor_ms"] = timing.contraction_seconds * 1e3;
  state.counters["sweep_ms"] = timing.sweep_seconds * 1e3;
  state.counters["x_floor"] = timing.sweep_seconds / timing.contraction_seconds;
  const double flops = 4.0 * 32 * 32 * static_cast<double>(t.blocks) * rank;
  state.counters["floor_GFLOPs"] = flops / timing.contraction_seconds * 1e-9;
}
BENCHMARK(BM_CpSweep)->Args({2048, 16})->Args({512, 16})->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

// Full decomposition of one 32x32x1024 group at rank 16: arg 0 = method, arg 1 = non-negative.
void BM_CpDecompose(benchmark::State& state) {
  const GroupTensor& t = tensorOf(1024);
  CpOptions o;
  o.method = static_cast<CpMethod>(state.range(0));
  o.nonneg = state.range(1) != 0;
  if (o.method == CpMethod::kAlsPlain) o.tol = 0.0;  // the baseline: exactly 500 sweeps
  double error = 0.0;
  int sweeps = 0, core_sweeps = 0;
  for (auto _ : state) {
    auto r = bake::tensor::decomposeCp(t, o);
    if (!r.ok()) {
      state.SkipWithError(r.error().message.c_str());
      return;
    }
    error = r.value().relative_error;
    sweeps = r.value().sweeps;
    core_sweeps = r.value().core_sweeps;
  }
  state.SetLabel(std::string(bake::tensor::cpMethodName(o.method)) + (o.nonneg ? "+nonneg" : ""));
  state.counters["rel_error"] = error;
  state.counters["sweeps"] = sweeps;
  state.counters["core_sweeps"] = core_sweeps;
}
BENCHMARK(BM_CpDecompose)
    ->Args({static_cast<int>(CpMethod::kAlsPlain), 0})
    ->Args({static_cast<int>(CpMethod::kAls), 0})
    ->Args({static_cast<int>(CpMethod::kCompressed), 0})
    ->Args({static_cast<int>(CpMethod::kCompressed), 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// Two rank-16 groups and an 8-way blend of their blocks (4 per group, like the two pyramid levels
// of a trilinear lookup).
struct QueryFixture {
  struct Group {
    bake::tensor::CpFactors f;
    std::vector<float> pa, pb;
    runtime::CpGroupView view;
  };
  Group groups[2];
  runtime::CpBlendTerm terms[8];

  QueryFixture() {
    for (int g = 0; g < 2; ++g) {
      CpOptions o;
      o.nonneg = true;
      o.max_iters = 50;
      groups[g].f = bake::tensor::decomposeCp(bake::tensor::makeNdfLikeGroup(32, 128, 90 + g), o).value();
      auto& gr = groups[g];
      gr.pa = bake::tensor::buildPrefixSums(gr.f.a, 32, gr.f.rank);
      gr.pb = bake::tensor::buildPrefixSums(gr.f.b, 32, gr.f.rank);
      gr.view = {32, gr.f.rank, gr.f.blocks, gr.f.a.data(), gr.f.b.data(), gr.f.c.data(), gr.pa.data(), gr.pb.data()};
    }
    const float w[8] = {0.21f, 0.14f, 0.09f, 0.06f, 0.2f, 0.13f, 0.1f, 0.07f};
    for (int t = 0; t < 8; ++t) terms[t] = {&groups[t / 4].view, 7 + 9 * t, w[t]};
  }
};

QueryFixture& fixture() {
  static QueryFixture f;
  return f;
}

void BM_CpPoint(benchmark::State& state) {
  QueryFixture& f = fixture();
  uint32_t n = 0;
  for (auto _ : state) {
    runtime::CpMix mix;
    mix.init(f.terms, 8);
    benchmark::DoNotOptimize(mix.value(n & 31, (n >> 5) & 31));
    n += 37;
  }
}
BENCHMARK(BM_CpPoint);

void BM_CpRange(benchmark::State& state) {
  QueryFixture& f = fixture();
  uint32_t n = 0;
  for (auto _ : state) {
    runtime::CpMix mix;
    mix.init(f.terms, 8);
    const int i0 = n & 15, j0 = (n >> 4) & 15;
    benchmark::DoNotOptimize(mix.rangeAverage(i0, i0 + 9, j0, j0 + 13));
    n += 37;
  }
}
BENCHMARK(BM_CpRange);

void BM_CpSample(benchmark::State& state) {
  QueryFixture& f = fixture();
  std::mt19937_64 rng(5);
  auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  for (auto _ : state) {
    runtime::CpMix mix;
    mix.init(f.terms, 8);
    runtime::CpBlockSample s;
    benchmark::DoNotOptimize(mix.sample(uniform(), uniform(), &s));
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_CpSample);

void BM_CpPdf(benchmark::State& state) {
  QueryFixture& f = fixture();
  uint32_t n = 0;
  for (auto _ : state) {
    runtime::CpMix mix;
    mix.init(f.terms, 8);
    benchmark::DoNotOptimize(mix.pdf(n & 31, (n >> 5) & 31));
    n += 37;
  }
}
BENCHMARK(BM_CpPdf);

}  // namespace

BENCHMARK_MAIN();
