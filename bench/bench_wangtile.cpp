// SPDX-License-Identifier: Apache-2.0
// Wang-tiles assets (formats/SPEC.md 10.7): eval and sample cost for footprints covering 1, 4 and 9
// tiles of the implicit grid. The asset is GLINTBAKE_WANG_ASSET when set (e.g. a 16-tile set from
// a 1024^2 example at tile size 256, README "Figures"), otherwise a small set baked here (T = 32).
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/wang/wang.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/wang_ndf.h>

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

namespace {

namespace rt = glintbake::runtime;
namespace wang = glintbake::bake::wang;

std::vector<uint8_t> smallAsset() {
  glintbake::bake::MapParams mp;
  mp.size = 128;
  mp.alpha = 0.3;
  const auto set = wang::buildWangTiles(glintbake::bake::generateMap(glintbake::bake::MapKind::kBeckmann, mp), {2, 32});
  wang::WangNdfOptions o;
  o.pyramid.splat.ndf_res = 64;
  o.pyramid.sigma0 = 2.0;
  o.pyramid.stride0 = 4.0;
  o.pyramid.levels = 3;
  o.pack.block = 16;
  o.pack.cp.max_iters = 30;
  o.margin = 32;
  std::vector<std::vector<uint8_t>> tiles(16);
  const std::string path = "bench_wangtile_tile.tmp";
  for (int t = 0; t < 16; ++t) (void)wang::bakeWangTileNdf(set.value(), t, o, path, "{}", &tiles[size_t(t)], nullptr);
  const double max_sigma = glintbake::format::wangMaxSigma(32);
  const auto rec = wang::wangRecord(set.value(), o, 1, 2.0, 2.0 * 1.4142135623730951, max_sigma);
  glintbake::format::Writer w;
  const std::string file = "bench_wangtile.gbk.tmp";
  (void)w.open(file, glintbake::format::AssetKind::kWangTiles, 1);
  (void)wang::writeWangSections(w, set.value(), rec, tiles);
  (void)w.addMetadata("{}");
  (void)w.finish();
  std::ifstream f(file, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::remove(file.c_str());
  return bytes;
}

const rt::WangNdf& asset() {
  static std::unique_ptr<rt::NdfSource> src = [] {
    std::unique_ptr<rt::NdfSource> s;
    const char* path = std::getenv("GLINTBAKE_WANG_ASSET");
    if (path && *path) {
      if (rt::openNdfAsset(path, &s) != rt::RuntimeStatus::kOk) std::abort();
    } else {
      const std::vector<uint8_t> bytes = smallAsset();
      if (rt::openNdfAssetMemory(bytes.data(), bytes.size(), &s) != rt::RuntimeStatus::kOk) std::abort();
    }
    return s;
  }();
  return *static_cast<const rt::WangNdf*>(src.get());
}

// Footprints covering 1 (a tile's middle), 4 (a corner) and 9 tiles (the largest footprint at a
// tile's middle), at the pyramid's first answering sigma for 1 and 4.
rt::Footprint footprint(int tiles, int i) {
  const rt::WangNdf& a = asset();
  const double T = double(a.record().tile_size);
  const double jitter = 0.37 * (i % 7);
  const double sigma = tiles == 9 ? a.record().max_sigma : std::max(a.record().pyramid_from, 1.0);
  const double at = tiles == 4 ? 3.0 * T : 3.5 * T;
  return {at + jitter, at - jitter, sigma};
}

void label(benchmark::State& state, int tiles) {
  state.SetLabel(std::to_string(asset().coveredTiles(footprint(tiles, 0))) +
                 " tiles, T = " + std::to_string(asset().record().tile_size));
}

void BM_WangEval(benchmark::State& state) {
  const int tiles = int(state.range(0));
  (void)asset();  // loaded outside the timed loop
  int i = 0;
  for (auto _ : state) {
    double v = 0.0;
    benchmark::DoNotOptimize(asset().eval(footprint(tiles, i), {0.02 * (i % 5), -0.03 * (i % 3)}, &v));
    benchmark::DoNotOptimize(v);
    ++i;
  }
  label(state, tiles);
}
BENCHMARK(BM_WangEval)->Arg(1)->Arg(4)->Arg(9)->Unit(benchmark::kMicrosecond);

void BM_WangSample(benchmark::State& state) {
  const int tiles = int(state.range(0));
  (void)asset();  // loaded outside the timed loop
  int i = 0;
  for (auto _ : state) {
    rt::NdfSample s;
    benchmark::DoNotOptimize(asset().sample(footprint(tiles, i), (i % 97 + 0.5) / 97.0, (i % 89 + 0.5) / 89.0, &s));
    ++i;
  }
  label(state, tiles);
}
BENCHMARK(BM_WangSample)->Arg(1)->Arg(4)->Arg(9)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
