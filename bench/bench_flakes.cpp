// SPDX-License-Identifier: Apache-2.0
// Latency of the runtime's exact small-footprint evaluator (FlakeNdf): point eval, sample and the
// reference evaluator at the same footprints, on 1024^2 maps. By default three procedural maps
// (beckmann, scratches, flakes); GLINTBAKE_BENCH_MAPS=a.png,b.png benchmarks real maps instead.
// Queries cycle through 1024 precomputed random footprints and s-plane points drawn where the NDF
// is not negligible (sampled from it), so that caches and branch predictors see varied queries.
// GLINTBAKE_BENCH_ASSETS=a.gbk,b.gbk adds `asset_eval` and `asset_sample`: the same queries through
// baked NDF assets (openNdfAsset: flakes, lobes, pyramid and the blends between them) at footprints
// from 1 texel to past the pyramid's hand-over, so that every path and band of an asset is timed;
// `asset_eval_raster` the same evals over a block of neighbouring pixels' footprints;
// `asset_eval_each` and `asset_sample_each` the random queries timed one by one, with the median
// and 90th percentile over the queries as counters.
// `lobe_build` times the lobe hierarchy a reader builds at load (16 lobes per tile).
// `tile_ratio_probe` times the bake's probe of the tile ratio (bake::ndf::chooseLobeTileRatio),
// `handover_probe` its probe above an exact level (bake::ndf::probeExactLevelHandover).
#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/lobe_ndf.h>
#include <glintbake/runtime/ndf_source.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace bake = glintbake::bake;
namespace rt = glintbake::runtime;

// A normal map seen through the runtime's texel-source interface.
rt::InterleavedTexels mapTexels(const bake::NormalMap& map) {
  return rt::InterleavedTexels(map.width, map.height, map.wrap == bake::Wrap::kRepeat, map.normals.data(), 3);
}

struct Subject {
  std::string name;
  bake::NormalMap map;
  rt::FlakeNdf ndf;
  rt::LobeNdf lobes;
  glintbake::reference::FlakeSet set;
};

std::vector<std::unique_ptr<Subject>>& subjects() {
  static std::vector<std::unique_ptr<Subject>> all = [] {
    std::vector<std::unique_ptr<Subject>> v;
    const char* env = std::getenv("GLINTBAKE_BENCH_MAPS");
    if (env && *env) {
      std::stringstream list(env);
      std::string path;
      while (std::getline(list, path, ',')) {
        auto s = std::make_unique<Subject>();
        auto map = bake::loadNormalMap(path, bake::IngestOptions(), nullptr);
        if (!map.ok()) {
          std::fprintf(stderr, "bench_flakes: cannot read %s\n", path.c_str());
          std::abort();
        }
        s->map = std::move(map.value());
        s->name = path.substr(path.find_last_of('/') + 1);
        v.push_back(std::move(s));
      }
    } else {
      for (bake::MapKind kind : {bake::MapKind::kBeckmann, bake::MapKind::kScratches, bake::MapKind::kFlakes}) {
        auto s = std::make_unique<Subject>();
        bake::MapParams p;
        p.size = 1024;
        s->map = bake::generateMap(kind, p);
        s->name = bake::mapKindString(kind);
        v.push_back(std::move(s));
      }
    }
    for (auto& s : v) {
      const auto texels = mapTexels(s->map);
      if (s->ndf.build(texels, 1, 0.005, 128) != rt::RuntimeStatus::kOk) std::abort();
      if (s->lobes.build(texels, 1, 0.005, 16, 128) != rt::RuntimeStatus::kOk) std::abort();
      s->set = glintbake::reference::buildFlakes(s->map, 1);
    }
    return v;
  }();
  return all;
}

struct Query {
  rt::Footprint fp;
  rt::SPoint s;
  double u1, u2;
};

// raster: the footprints of a 32 x 32 block of pixels instead (centres 2 sigma apart, at least a
// texel: a pixel's footprint std is about half its spacing), in scanline order, as a renderer's
// neighbouring pixels query the same surface; random footprints over the whole map are the cold
// worst case.
std::vector<Query> queries(const rt::NdfSource& source, int width, int height, double sigma, bool raster = false) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Query> q(1024);
  // The raster's corner is drawn only for a raster, so that the random footprints stay the same.
  const double x0 = raster ? u(rng) * width : 0.0, y0 = raster ? u(rng) * height : 0.0;
  const double spacing = std::max(2.0 * sigma, 1.0);
  for (size_t k = 0; k < q.size(); ++k) {
    Query& x = q[k];
    x.fp = raster ? rt::Footprint{x0 + double(k % 32) * spacing, y0 + double(k / 32) * spacing, sigma}
                  : rt::Footprint{u(rng) * width, u(rng) * height, sigma};
    rt::NdfSample smp;
    // A point where the NDF is not negligible: a sample of it (retry the rare rejected tail).
    int tries = 0;
    do {
      if (++tries > 1000) std::abort();  // an NDF that never yields a sample: no benchmark
      source.sample(x.fp, u(rng), u(rng), &smp);
    } while (!(smp.pdf > 0.0));
    x.s = smp.s;
    x.u1 = u(rng);
    x.u2 = u(rng);
  }
  return q;
}
std::vector<Query> queries(const Subject& subject, double sigma) {
  return queries(subject.ndf, subject.map.width, subject.map.height, sigma);
}

// The baked assets of GLINTBAKE_BENCH_ASSETS.
struct AssetSubject {
  std::string name;
  std::unique_ptr<rt::NdfSource> source;
};
std::vector<AssetSubject>& assets() {
  static std::vector<AssetSubject> all = [] {
    std::vector<AssetSubject> v;
    const char* env = std::getenv("GLINTBAKE_BENCH_ASSETS");
    if (!env || !*env) return v;
    std::stringstream list(env);
    std::string path;
    while (std::getline(list, path, ',')) {
      AssetSubject a;
      if (rt::openNdfAsset(path.c_str(), &a.source) != rt::RuntimeStatus::kOk) {
        std::fprintf(stderr, "bench_flakes: cannot open %s\n", path.c_str());
        std::abort();
      }
      a.name = path.substr(path.find_last_of('/') + 1);
      v.push_back(std::move(a));
    }
    return v;
  }();
  return all;
}

void assetBench(benchmark::State& state, size_t index, double sigma, bool sample, bool raster) {
  const rt::NdfSource& src = *assets()[index].source;
  const rt::MapSize size = src.mapSize();
  const std::vector<Query> q = queries(src, int(size.width), int(size.height), sigma, raster);
  size_t i = 0;
  for (auto _ : state) {
    if (sample) {
      rt::NdfSample smp;
      src.sample(q[i].fp, q[i].u1, q[i].u2, &smp);
      benchmark::DoNotOptimize(smp);
    } else {
      double v;
      src.eval(q[i].fp, q[i].s, &v);
      benchmark::DoNotOptimize(v);
    }
    i = (i + 1) & 1023;
  }
}

// The same random queries, each timed on its own (the clock read's own cost, measured alike,
// taken off), a query an iteration (the 1024 in turn): the reported time is the mean per query, and
// the counters give the median and 90th percentile over every query timed, as the targets are
// stated (a median over random queries).
void assetQueryBench(benchmark::State& state, size_t index, double sigma, bool sample) {
  using Clock = std::chrono::steady_clock;
  const rt::NdfSource& src = *assets()[index].source;
  const rt::MapSize size = src.mapSize();
  const std::vector<Query> q = queries(src, int(size.width), int(size.height), sigma);
  std::vector<double> overhead(4096);
  for (double& o : overhead) {
    const auto t0 = Clock::now();
    const auto t1 = Clock::now();
    o = std::chrono::duration<double>(t1 - t0).count();
  }
  std::nth_element(overhead.begin(), overhead.begin() + overhead.size() / 2, overhead.end());
  const double clock_cost = overhead[overhead.size() / 2];
  std::vector<double> times;
  size_t i = 0;
  for (auto _ : state) {
    const Query& x = q[i];
    const auto t0 = Clock::now();
    if (sample) {
      rt::NdfSample smp;
      src.sample(x.fp, x.u1, x.u2, &smp);
      benchmark::DoNotOptimize(smp);
    } else {
      double v;
      src.eval(x.fp, x.s, &v);
      benchmark::DoNotOptimize(v);
    }
    const auto t1 = Clock::now();
    const double t = std::max(std::chrono::duration<double>(t1 - t0).count() - clock_cost, 0.0);
    times.push_back(t);
    state.SetIterationTime(t);
    i = (i + 1) & 1023;
  }
  if (times.empty()) return;
  auto quantile = [&times](double p) {
    const auto k = times.begin() + std::ptrdiff_t(p * double(times.size() - 1));
    std::nth_element(times.begin(), k, times.end());
    return *k;
  };
  state.counters["median_us"] = 1e6 * quantile(0.5);
  state.counters["p90_us"] = 1e6 * quantile(0.9);
}

// One untimed pass over the queries: the lobe evaluator builds a level on its first query there
// (hundreds of milliseconds), which a timed run of few iterations would otherwise count.
void warmUp(const rt::NdfSource& src, const std::vector<Query>& q) {
  for (const Query& x : q) {
    double v;
    src.eval(x.fp, x.s, &v);
    benchmark::DoNotOptimize(v);
  }
}

// Point eval and sample of one of a subject's evaluators (the exact flakes or the clustered lobes).
const rt::NdfSource& evaluator(const Subject& s, bool lobes) {
  return lobes ? static_cast<const rt::NdfSource&>(s.lobes) : s.ndf;
}

void evalBench(benchmark::State& state, size_t subject, double sigma, bool lobes) {
  const Subject& s = *subjects()[subject];
  const rt::NdfSource& src = evaluator(s, lobes);
  const std::vector<Query> q = queries(s, sigma);
  warmUp(src, q);
  size_t i = 0;
  for (auto _ : state) {
    double v;
    src.eval(q[i].fp, q[i].s, &v);
    benchmark::DoNotOptimize(v);
    i = (i + 1) & 1023;
  }
}

void sampleBench(benchmark::State& state, size_t subject, double sigma, bool lobes) {
  const Subject& s = *subjects()[subject];
  const rt::NdfSource& src = evaluator(s, lobes);
  const std::vector<Query> q = queries(s, sigma);
  warmUp(src, q);
  size_t i = 0;
  for (auto _ : state) {
    rt::NdfSample smp;
    src.sample(q[i].fp, q[i].u1, q[i].u2, &smp);
    benchmark::DoNotOptimize(smp);
    i = (i + 1) & 1023;
  }
}

// What loading an asset with flakes costs: the lobe hierarchy of the whole map (16 lobes per tile).
void lobeBuildBench(benchmark::State& state, size_t subject) {
  const Subject& s = *subjects()[subject];
  const auto texels = mapTexels(s.map);
  for (auto _ : state) {
    rt::LobeNdf lobes;
    if (lobes.build(texels, 1, 0.005, 16, 128) != rt::RuntimeStatus::kOk) std::abort();
    lobes.prepare();  // every level, as a reader that queries them all pays
    benchmark::DoNotOptimize(&lobes);
  }
}

// The bake's choice of the clustered path's tile ratio (bake::ndf::chooseLobeTileRatio) with the
// lobes answering up to 45 texels, so that every probe footprint runs: maps of more than
// kLobeProbeMaxFlakes flakes are probed on a window at their centre (GLINTBAKE_BENCH_MAPS=a 4096^2
// map shows the bound).
void tileRatioProbeBench(benchmark::State& state, size_t subject) {
  const Subject& s = *subjects()[subject];
  const auto texels = mapTexels(s.map);
  for (auto _ : state) benchmark::DoNotOptimize(bake::ndf::chooseLobeTileRatio(texels, 1, 0.005, 16, 64.0));
}

// The hand-over probe above an exact level of 32 texels, as tensorpack runs it on a 1024^2 map
// (levels of the default geometry from there up).
void handoverProbeBench(benchmark::State& state, size_t subject) {
  const Subject& s = *subjects()[subject];
  const auto texels = mapTexels(s.map);
  std::vector<bake::ndf::PyramidLevelShape> levels;
  for (int l = 2; l < 5; ++l) {
    const bake::ndf::LevelGeometry g = bake::ndf::levelGeometry(s.map.width, s.map.height, {}, l, true);
    levels.push_back({g.sigma, g.grid_width, g.grid_height});
  }
  for (auto _ : state) {
    const bake::ndf::HandoverProbe p = bake::ndf::probeExactLevelHandover(
        texels, 1, 0.005, 16, levels.data(), int(levels.size()), std::sqrt(2.0) * levels[0].sigma);
    benchmark::DoNotOptimize(p);
  }
}

void referenceBench(benchmark::State& state, size_t subject, double sigma) {
  const Subject& s = *subjects()[subject];
  const std::vector<Query> q = queries(s, sigma);
  size_t i = 0;
  for (auto _ : state) {
    const double v =
        glintbake::reference::evalPndf(s.set, {q[i].fp.x, q[i].fp.y, std::max(sigma, 1e-6)}, q[i].s.x, q[i].s.y, 0.005);
    benchmark::DoNotOptimize(v);
    i = (i + 1) & 1023;
  }
}

const int registered = [] {
  for (size_t k = 0; k < subjects().size(); ++k) {
    const std::string name = subjects()[k]->name;
    for (double sigma : {0.0, 1.0, 4.0, 8.0, 16.0}) {
      const std::string tag = name + "/sigma:" + std::to_string(int(sigma));
      benchmark::RegisterBenchmark(("flake_eval/" + tag).c_str(), evalBench, k, sigma, false);
      benchmark::RegisterBenchmark(("flake_sample/" + tag).c_str(), sampleBench, k, sigma, false);
    }
    for (double sigma : {6.0, 12.0, 24.0, 48.0}) {
      const std::string tag = name + "/sigma:" + std::to_string(int(sigma));
      benchmark::RegisterBenchmark(("lobe_eval/" + tag).c_str(), evalBench, k, sigma, true)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("lobe_sample/" + tag).c_str(), sampleBench, k, sigma, true)
          ->Unit(benchmark::kMicrosecond);
    }
    benchmark::RegisterBenchmark(("lobe_build/" + name).c_str(), lobeBuildBench, k)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(3);
    benchmark::RegisterBenchmark(("tile_ratio_probe/" + name).c_str(), tileRatioProbeBench, k)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1);
    benchmark::RegisterBenchmark(("handover_probe/" + name).c_str(), handoverProbeBench, k)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1);
    benchmark::RegisterBenchmark(("reference_eval/" + name + "/sigma:4").c_str(), referenceBench, k, 4.0)
        ->Unit(benchmark::kMicrosecond);
  }
  for (size_t k = 0; k < assets().size(); ++k) {
    for (double sigma :
         {1.0, 4.0, 5.0, 8.0, 12.0, 16.0, 20.0, 22.0, 24.0, 28.0, 32.0, 40.0, 48.0, 64.0, 96.0, 128.0, 160.0, 256.0}) {
      const std::string tag = assets()[k].name + "/sigma:" + std::to_string(int(sigma));
      benchmark::RegisterBenchmark(("asset_eval/" + tag).c_str(), assetBench, k, sigma, false, false)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("asset_sample/" + tag).c_str(), assetBench, k, sigma, true, false)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("asset_eval_raster/" + tag).c_str(), assetBench, k, sigma, false, true)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("asset_eval_each/" + tag).c_str(), assetQueryBench, k, sigma, false)
          ->Unit(benchmark::kMicrosecond)
          ->UseManualTime();
      benchmark::RegisterBenchmark(("asset_sample_each/" + tag).c_str(), assetQueryBench, k, sigma, true)
          ->Unit(benchmark::kMicrosecond)
          ->UseManualTime();
    }
  }
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();
