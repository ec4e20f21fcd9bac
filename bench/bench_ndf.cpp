// SPDX-License-Identifier: Apache-2.0
// NDF image generation per footprint (splat vs reference, one thread each) and runtime query
// latency (eval, sample, average) on a baked pyramid.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/ndf/splat.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/ndf_pyramid.h>

#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace {

namespace bake = glintbake::bake;
namespace ndf = glintbake::bake::ndf;

const bake::NormalMap& benchMap() {
  static const bake::NormalMap map = [] {
    bake::MapParams p;
    p.size = 256;
    p.seed = 42;
    return bake::generateMap(bake::MapKind::kBeckmann, p);
  }();
  return map;
}

// Splats the image of a footprint of sigma = the benchmark's argument at one position.
void splatImages(benchmark::State& state, const ndf::FlakeSet& flakes) {
  ndf::SplatParams params;  // R = 128, sigma_r = 0.005
  ndf::Splatter splatter(flakes, params);
  std::vector<float> img(size_t(params.ndf_res) * params.ndf_res);
  const double sigma = double(state.range(0));
  int64_t lobes = 0;
  for (auto _ : state) {
    lobes = splatter.image(100.3, 57.8, sigma, img.data());
    benchmark::DoNotOptimize(img.data());
  }
  state.counters["lobes"] = double(lobes);
}

// Sigma 128 on the 256^2 map: a footprint wider than the map, whose flakes' periodic images are
// folded into one lobe each.
void BM_SplatImage(benchmark::State& state) {
  static const ndf::FlakeSet flakes = ndf::buildFlakes(benchMap(), 1).value();
  splatImages(state, flakes);
}
BENCHMARK(BM_SplatImage)->Arg(2)->Arg(8)->Arg(32)->Arg(128)->Unit(benchmark::kMillisecond);

// The same on dense sharp flakes (a normal cone of 60 degrees, cells of 3 texels): nearly every
// texel straddles an edge between flakes, so its lobe is a streak across much of the image (or a
// wide lobe where three or four flakes meet), the splat's most expensive case.
void BM_SplatImageSharpFlakes(benchmark::State& state) {
  static const ndf::FlakeSet flakes = [] {
    bake::MapParams p;
    p.size = 256;
    p.seed = 9;
    p.cone_degrees = 60.0;
    p.cell = 3.0;
    return ndf::buildFlakes(bake::generateMap(bake::MapKind::kFlakes, p), 1).value();
  }();
  splatImages(state, flakes);
}
BENCHMARK(BM_SplatImageSharpFlakes)->Arg(8)->Arg(32)->Arg(128)->Unit(benchmark::kMillisecond);

void BM_ReferenceImage(benchmark::State& state) {
  static const glintbake::reference::FlakeSet flakes = glintbake::reference::buildFlakes(benchMap(), 1);
  glintbake::reference::Footprint fp;
  fp.x = 100.3;
  fp.y = 57.8;
  fp.sigma = double(state.range(0));
  tbb::task_arena one_thread(1);  // same thread budget as the splat
  for (auto _ : state) {
    one_thread.execute([&] {
      std::vector<double> img = glintbake::reference::binAveragedImage(flakes, fp, 0.005, 128);
      benchmark::DoNotOptimize(img.data());
    });
  }
}
BENCHMARK(BM_ReferenceImage)->Arg(2)->Arg(8)->Arg(32)->Unit(benchmark::kMillisecond)->Iterations(1);

// A pyramid over a 64^2 map, baked once.
const glintbake::runtime::NdfPyramid& benchPyramid() {
  static std::unique_ptr<glintbake::runtime::NdfPyramid> pyramid = [] {
    bake::MapParams p;
    p.size = 64;
    const bake::NormalMap map = bake::generateMap(bake::MapKind::kBeckmann, p);
    ndf::PyramidOptions o;
    o.stride0 = 8;
    o.sigma0 = 4;
    o.levels = 3;
    const std::string path = "bench_ndf_pyramid.gbk";
    glintbake::format::Writer w;
    if (w.open(path, glintbake::format::AssetKind::kNdfPyramid, 1) != glintbake::format::ContainerStatus::kOk ||
        !ndf::buildNdfPyramid(map, o, w, nullptr).ok() ||
        w.addMetadata("{}") != glintbake::format::ContainerStatus::kOk ||
        w.finish() != glintbake::format::ContainerStatus::kOk) {
      std::fprintf(stderr, "cannot bake the benchmark pyramid\n");
      std::abort();
    }
    auto pyr = std::make_unique<glintbake::runtime::NdfPyramid>();
    if (pyr->open(path.c_str()) != glintbake::runtime::RuntimeStatus::kOk) std::abort();
    std::remove(path.c_str());
    return pyr;
  }();
  return *pyramid;
}

glintbake::runtime::Footprint footprintAt(int k) {
  glintbake::runtime::Footprint f;
  f.x = 3.7 + (k % 61);
  f.y = 11.1 + (k % 37);
  f.sigma = 3.0 + (k % 13);
  return f;
}

void BM_RuntimeEval(benchmark::State& state) {
  const auto& pyr = benchPyramid();
  int k = 0;
  double v = 0.0;
  for (auto _ : state) {
    pyr.eval(footprintAt(k++), glintbake::runtime::SPoint{0.01 * (k % 7), -0.02}, &v);
    benchmark::DoNotOptimize(v);
  }
}
BENCHMARK(BM_RuntimeEval);

void BM_RuntimeSample(benchmark::State& state) {
  const auto& pyr = benchPyramid();
  int k = 0;
  glintbake::runtime::NdfSample s;
  for (auto _ : state) {
    pyr.sample(footprintAt(k), (k % 1000) * 0.000999, ((k * 7) % 1000) * 0.000999, &s);
    ++k;
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_RuntimeSample);

void BM_RuntimeAverage(benchmark::State& state) {
  const auto& pyr = benchPyramid();
  int k = 0;
  double v = 0.0;
  glintbake::runtime::SRect r;
  r.x0 = -0.05;
  r.x1 = 0.05;
  r.y0 = -0.05;
  r.y1 = 0.05;  // about 6 x 6 bins of R = 128
  for (auto _ : state) {
    pyr.average(footprintAt(k++), r, &v);
    benchmark::DoNotOptimize(v);
  }
}
BENCHMARK(BM_RuntimeAverage);

}  // namespace

BENCHMARK_MAIN();
