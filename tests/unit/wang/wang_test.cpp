// SPDX-License-Identifier: Apache-2.0
// Wang tiles: exact shared edges, the clamped tiles continuing as the grid does, the implicit grid
// against the same region materialised as one map (reference evaluator and splatter), tile
// frequencies, the sampler (chi-square, footprints straddling a corner), the clamp of large
// footprints, and malformed assets.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/flakes.h>
#include <glintbake/bake/ndf/splat.h>
#include <glintbake/bake/wang/wang.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/wang.h>
#include <glintbake/reference/flakes.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/wang_ndf.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>
#include "../temp_dir.h"
#include "stats/chi_square.h"

namespace glintbake {
namespace {

constexpr int kT = 16;         // tile size of the tests
constexpr int kRes = 32;       // NDF resolution
constexpr uint64_t kGrid = 7;  // grid seed
constexpr int kRegion = 4;     // cells per side of the materialised region

bake::NormalMap example() {
  bake::MapParams p;
  p.size = 64;
  p.seed = 5;
  p.alpha = 0.25;
  p.cell = 2.0;
  return bake::generateMap(bake::MapKind::kBeckmann, p);
}

const bake::wang::WangTileSet& tileSet() {
  static const bake::wang::WangTileSet set = [] {
    bake::wang::WangTileOptions o;
    o.tile_size = kT;
    o.seed = 3;
    auto r = bake::wang::buildWangTiles(example(), o);
    EXPECT_TRUE(bool(r));
    return r.value();
  }();
  return set;
}

bake::wang::WangNdfOptions ndfOptions(bool uncompressed) {
  bake::wang::WangNdfOptions o;
  o.pyramid.splat.ndf_res = kRes;
  o.pyramid.sigma0 = 1.0;
  o.pyramid.stride0 = 2.0;
  o.pyramid.levels = 3;  // sigma 1, 2, 4 ~ the largest footprint of T = 16
  o.pyramid.region_size = 8;
  o.pack.cp.rank = 8;
  o.pack.block = 16;
  o.pack.cp.max_iters = 50;
  o.uncompressed = uncompressed;
  o.margin = kT;
  o.zstd_level = 1;
  return o;
}

// The asset bytes of the test tile set: uncompressed tiles (exact pyramid images) or compressed.
const std::vector<uint8_t>& assetBytes(bool uncompressed, double* max_tile_error = nullptr) {
  static std::map<bool, std::vector<uint8_t>> cache;
  static double compressed_error = 0.0;
  if (!cache.count(uncompressed)) {
    const auto& set = tileSet();
    const auto o = ndfOptions(uncompressed);
    std::vector<std::vector<uint8_t>> tiles(size_t(set.tile_count));
    for (int t = 0; t < set.tile_count; ++t) {
      bake::wang::WangTileNdfReport rep;
      const std::string path = testing::processTempDir() + "tile.gbk";
      EXPECT_TRUE(bool(bake::wang::bakeWangTileNdf(set, t, o, path, "{}", &tiles[size_t(t)], &rep)));
      if (!uncompressed) compressed_error = std::max(compressed_error, rep.pack.relative_error);
    }
    const double max_sigma = format::wangMaxSigma(kT);
    const format::WangRecord rec = bake::wang::wangRecord(set, o, kGrid, 1.0, 1.0 * std::sqrt(2.0), max_sigma);
    const std::string file = testing::processTempDir() + (uncompressed ? "wang_u.gbk" : "wang_c.gbk");
    format::Writer w;
    EXPECT_EQ(w.open(file, format::AssetKind::kWangTiles, 1), format::ContainerStatus::kOk);
    EXPECT_TRUE(bool(bake::wang::writeWangSections(w, set, rec, tiles)));
    EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
    std::ifstream f(file, std::ios::binary);
    cache[uncompressed] = std::vector<uint8_t>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  if (max_tile_error) *max_tile_error = compressed_error;
  return cache[uncompressed];
}

std::unique_ptr<runtime::NdfSource> openAsset(bool uncompressed) {
  const auto& bytes = assetBytes(uncompressed);
  std::unique_ptr<runtime::NdfSource> src;
  EXPECT_EQ(runtime::openNdfAssetMemory(bytes.data(), bytes.size(), &src), runtime::RuntimeStatus::kOk);
  return src;
}

// The materialised region: cells [0, 4) x [0, 4) of the grid as one clamped map.
const bake::NormalMap& region() {
  static const bake::NormalMap m = bake::wang::materialiseWangRegion(tileSet(), kGrid, 0, 0, kRegion, kRegion);
  return m;
}

double relL1(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0, n = 0.0;
  for (size_t i = 0; i < a.size(); ++i) d += std::fabs(a[i] - b[i]), n += std::fabs(b[i]);
  return n > 0.0 ? d / n : d;
}

TEST(WangTiles, SharedEdgesMatchExactly) {
  const auto& set = tileSet();
  ASSERT_EQ(set.tile_count, 16);
  for (int a = 0; a < set.tile_count; ++a) {
    for (int b = 0; b < set.tile_count; ++b) {
      // b to the east of a, and b below a: the texels on both sides of the edge are the same
      // exemplar line, so the last column of a is the first of b (likewise rows).
      if (set.edges[size_t(a)][format::kWangEast] == set.edges[size_t(b)][format::kWangWest]) {
        for (int y = 0; y < kT; ++y)
          ASSERT_EQ(std::memcmp(set.texel(a, kT - 1, y), set.texel(b, 0, y), 12), 0) << a << " " << b << " " << y;
      }
      if (set.edges[size_t(a)][format::kWangSouth] == set.edges[size_t(b)][format::kWangNorth]) {
        ASSERT_EQ(std::memcmp(set.texel(a, 0, kT - 1), set.texel(b, 0, 0), size_t(kT) * 12), 0) << a << " " << b;
      }
    }
  }
  std::printf("[ measured ] seams: %.3f deg mean, %.3f max (plain cut %.3f mean, %.3f max) over %llu texels\n",
              set.seam.mean_degrees, set.seam.max_degrees, set.plain_seam.mean_degrees, set.plain_seam.max_degrees,
              static_cast<unsigned long long>(set.seam.texels));
  EXPECT_LE(set.seam.mean_degrees, set.plain_seam.mean_degrees);
}

TEST(WangTiles, TilesAreCutFromTheirEdgeSamples) {
  // Near each edge's middle a tile shows its edge sample: tiles with the same north colour agree on
  // their first rows away from the corners.
  const auto& set = tileSet();
  for (int a = 0; a < set.tile_count; ++a) {
    for (int b = 0; b < set.tile_count; ++b) {
      if (set.edges[size_t(a)][format::kWangNorth] != set.edges[size_t(b)][format::kWangNorth]) continue;
      EXPECT_EQ(std::memcmp(set.texel(a, kT / 2, 1), set.texel(b, kT / 2, 1), 12), 0);
    }
  }
}

// Every flake of the grid (normal and Jacobian by central differences across tile edges) equals
// the flake of its tile read alone with clamped edges: what lets each tile carry only its flakes.
TEST(WangTiles, ClampedTilesContinueAsTheGrid) {
  const auto& set = tileSet();
  const bake::NormalMap big = bake::wang::materialiseWangRegion(set, kGrid, 10, -3, 3, 3);
  auto whole = bake::ndf::buildFlakes(big, 1);
  ASSERT_TRUE(bool(whole));
  uint8_t e[4];
  format::wangCellEdges(11, -2, 2, kGrid, e);
  const int t = int(format::wangTileCode(2, e));
  auto own = bake::ndf::buildFlakes(set.tile(t), 1);
  ASSERT_TRUE(bool(own));
  for (int y = 0; y < kT; ++y) {
    for (int x = 0; x < kT; ++x) {
      const float* a = whole.value().flake(kT + x, kT + y);
      const float* b = own.value().flake(x, y);
      for (int k = 0; k < bake::ndf::kFlakeFloats; ++k) ASSERT_EQ(a[k], b[k]) << x << " " << y << " " << k;
    }
  }
}

TEST(WangTiles, NeighboursShareEdgeColoursAndFrequenciesAreUniform) {
  constexpr int n = 256;
  std::vector<int> count(16, 0);
  std::vector<uint32_t> row(n);
  for (int64_t j = -n / 2; j < n / 2; ++j) {
    for (int64_t i = -n / 2; i < n / 2; ++i) {
      uint8_t e[4], east[4], south[4];
      format::wangCellEdges(i, j, 2, kGrid, e);
      format::wangCellEdges(i + 1, j, 2, kGrid, east);
      format::wangCellEdges(i, j + 1, 2, kGrid, south);
      ASSERT_EQ(e[format::kWangEast], east[format::kWangWest]);
      ASSERT_EQ(e[format::kWangSouth], south[format::kWangNorth]);
      const uint32_t code = format::wangTileCode(2, e);
      ++count[code];
      if (j == 0) row[size_t(i + n / 2)] = code;
    }
  }
  double chi2 = 0.0;
  const double expected = double(n) * n / 16.0;
  for (int c : count) chi2 += (c - expected) * (c - expected) / expected;
  std::printf("[ measured ] tile frequencies over %d^2 cells: chi-square %.2f (15 dof)\n", n, chi2);
  EXPECT_LT(chi2, 37.7);  // p = 0.001
  // No period shorter than the region along a row.
  for (int p = 1; p < n / 2; ++p) {
    bool periodic = true;
    for (int i = 0; i + p < n && periodic; ++i) periodic = row[size_t(i)] == row[size_t(i + p)];
    EXPECT_FALSE(periodic) << p;
  }
}

// Footprints inside the materialised region, at tile interiors, edges and corners.
std::vector<runtime::Footprint> footprints(double sigma) {
  return {{24.3, 21.7, sigma}, {32.0, 20.5, sigma}, {16.0, 48.0, sigma}, {31.6, 32.4, sigma}, {40.0, 40.0, sigma}};
}

TEST(WangNdf, ImplicitGridMatchesReferenceOnMaterialisedRegionExactPath) {
  const auto src = openAsset(true);
  ASSERT_TRUE(src);
  const reference::FlakeSet ref = reference::buildFlakes(region(), 1);
  ASSERT_EQ(src->kind(), format::AssetKind::kWangTiles);
  // The grid covers the plane without a period: callers must not wrap positions into one tile.
  EXPECT_EQ(src->wrap(), runtime::MapWrap::kUnbounded);
  const runtime::WangGridTexels texels(static_cast<const runtime::WangNdf&>(*src), 0, 0, kRegion, kRegion);
  runtime::FlakeNdf grid_flakes;
  ASSERT_EQ(grid_flakes.build(texels, 1, reference::kDefaultSigmaR, kRes), runtime::RuntimeStatus::kOk);
  double worst = 0.0;
  for (double sigma : {0.5, 1.0}) {
    for (const runtime::Footprint& f : footprints(sigma)) {
      std::vector<double> a, b;
      for (int j = 0; j < 24; ++j) {
        for (int i = 0; i < 24; ++i) {
          const double sx = -0.6 + 1.2 * (i + 0.5) / 24, sy = -0.6 + 1.2 * (j + 0.5) / 24;
          double v = 0.0;
          ASSERT_EQ(src->eval(f, {sx, sy}, &v), runtime::RuntimeStatus::kOk);
          a.push_back(v);
          b.push_back(reference::evalPndf(ref, {f.x, f.y, f.sigma}, sx, sy, reference::kDefaultSigmaR));
        }
      }
      const double e = relL1(a, b);
      // The same region through the runtime's own flake evaluator over the grid's texels.
      std::vector<double> c;
      for (int j = 0; j < 24; ++j) {
        for (int i = 0; i < 24; ++i) {
          double v = 0.0;
          grid_flakes.eval(f, {-0.6 + 1.2 * (i + 0.5) / 24, -0.6 + 1.2 * (j + 0.5) / 24}, &v);
          c.push_back(v);
        }
      }
      EXPECT_LT(relL1(a, c), 1e-6) << f.x << " " << f.y << " " << sigma;
      double m = 0.0;
      src->mass(f, &m);
      EXPECT_LT(e, 1e-4) << f.x << " " << f.y << " " << sigma;
      worst = std::max(worst, e);
      EXPECT_NEAR(m, reference::footprintWeight(ref, {f.x, f.y, f.sigma}), 1e-6);
    }
  }
  std::printf("[ measured ] implicit grid vs reference on the materialised region, exact path: relative L1 %.2e\n",
              worst);
}

// The pyramid path: the uncompressed tiles' pyramids (centres aligned with the grid) against the
// ndf-pyramid baked from the materialised region with the same options. The runtime's blend is
// linear in the stored images and the region's images at each centre are the sums of the tiles'
// (each tile splatting its own flakes), so the two agree but for summation order and the blend's
// reach beyond a tile's extended square; the reference evaluator bounds both.
TEST(WangNdf, ImplicitGridMatchesMaterialisedRegionPyramidPath) {
  const auto src = openAsset(true);
  ASSERT_TRUE(src);
  const bake::NormalMap big = bake::wang::materialiseWangRegion(tileSet(), kGrid, 0, 0, 6, 6);
  const std::string file = testing::processTempDir() + "region.gbk";
  {
    format::Writer w;
    ASSERT_EQ(w.open(file, format::AssetKind::kNdfPyramid, 1), format::ContainerStatus::kOk);
    ASSERT_TRUE(bool(bake::ndf::buildNdfPyramid(big, ndfOptions(true).pyramid, w, nullptr)));
    ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
  }
  std::unique_ptr<runtime::NdfSource> explicit_src;
  ASSERT_EQ(runtime::openNdfAsset(file.c_str(), &explicit_src), runtime::RuntimeStatus::kOk);
  const reference::FlakeSet ref = reference::buildFlakes(big, 1);
  double worst = 0.0, worst_ref = 0.0;
  for (double sigma : {1.5, 2.0, 3.0}) {
    // Tile interiors, an edge, a corner (cells are 16 texels; the region's middle is 48).
    const double at[][2] = {{40.3, 41.7}, {48.0, 43.5}, {48.0, 48.0}, {47.2, 49.1}, {55.5, 52.5}};
    for (const auto& p : at) {
      const runtime::Footprint f{p[0], p[1], sigma};
      std::vector<float> img(size_t(kRes) * kRes), exp(size_t(kRes) * kRes);
      ASSERT_EQ(src->image(f, img.data(), img.size()), runtime::RuntimeStatus::kOk);
      ASSERT_EQ(explicit_src->image(f, exp.data(), exp.size()), runtime::RuntimeStatus::kOk);
      const std::vector<double> a(img.begin(), img.end()), b(exp.begin(), exp.end());
      const std::vector<double> r =
          reference::binAveragedImage(ref, {f.x, f.y, sigma}, reference::kDefaultSigmaR, kRes);
      worst = std::max(worst, relL1(a, b));
      worst_ref = std::max(worst_ref, std::fabs(relL1(a, r) - relL1(b, r)));
    }
  }
  std::printf(
      "[ measured ] implicit vs materialised region, uncompressed tiles: relative L1 %.2e; their distances "
      "to the reference differ by at most %.2e\n",
      worst, worst_ref);
  EXPECT_LT(worst, 1e-4);
}

TEST(WangNdf, CompressedTilesWithinTheirCompressionError) {
  double tile_error = 0.0;
  assetBytes(false, &tile_error);
  const auto c = openAsset(false), u = openAsset(true);
  ASSERT_TRUE(c && u);
  double d2 = 0.0, n2 = 0.0;
  for (const runtime::Footprint& f : footprints(2.0)) {
    std::vector<float> a(size_t(kRes) * kRes), b(size_t(kRes) * kRes);
    ASSERT_EQ(c->image(f, a.data(), a.size()), runtime::RuntimeStatus::kOk);
    ASSERT_EQ(u->image(f, b.data(), b.size()), runtime::RuntimeStatus::kOk);
    for (size_t i = 0; i < a.size(); ++i) d2 += double(a[i] - b[i]) * (a[i] - b[i]), n2 += double(b[i]) * b[i];
  }
  const double e = std::sqrt(d2 / n2);
  std::printf("[ measured ] compressed vs uncompressed tiles: relative error %.4f (largest tile's own %.4f)\n", e,
              tile_error);
  EXPECT_LT(e, 1.5 * tile_error + 1e-3);
}

TEST(WangNdf, SamplerPassesChiSquareAcrossCorners) {
  const auto src = openAsset(true);
  ASSERT_TRUE(src);
  struct S {
    double sx, sy;
  };
  // At a tile corner: the exact path, the hand-over band, the tiles' pyramids; and the clamp.
  for (double sigma : {0.8, 1.2, 3.0}) {
    const runtime::Footprint f{2.0 * kT + 0.3, 2.0 * kT - 0.2, sigma};
    const int res = 8, sub = 6;
    double m = 0.0;
    ASSERT_EQ(src->mass(f, &m), runtime::RuntimeStatus::kOk);
    std::vector<double> image(size_t(res) * res, 0.0);
    const double h = 2.0 / res;
    for (int j = 0; j < res; ++j) {
      for (int i = 0; i < res; ++i) {
        runtime::SRect r{-1 + i * h, 1 - (j + 1) * h, -1 + (i + 1) * h, 1 - j * h};
        double avg = 0.0;
        ASSERT_EQ(src->average(f, r, &avg), runtime::RuntimeStatus::kOk);
        image[size_t(j) * res + i] = avg;
      }
    }
    (void)sub;
    std::vector<S> samples;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 4000; ++k) {
      runtime::NdfSample smp;
      ASSERT_EQ(src->sample(f, u(rng), u(rng), &smp), runtime::RuntimeStatus::kOk);
      double p = 0.0, e = 0.0;
      src->pdf(f, smp.s, &p);
      src->eval(f, smp.s, &e);
      ASSERT_EQ(p, smp.pdf);
      ASSERT_EQ(p, m > 0 ? e / m : 0.0);
      samples.push_back({smp.s.x, smp.s.y});
    }
    const stats::ChiSquareResult r = stats::chiSquareNdfTest(samples, image, res, m);
    std::printf("[ measured ] wang sampler at a corner, sigma %.1f: chi-square p = %.4f\n", sigma, r.p_value);
    EXPECT_GT(r.p_value, 0.01) << sigma;
  }
}

TEST(WangNdf, LargeFootprintsAreClampedAndCoverAtMostNineTiles) {
  const auto src = openAsset(true);
  ASSERT_TRUE(src);
  ASSERT_EQ(src->kind(), format::AssetKind::kWangTiles);
  const auto* w = static_cast<const runtime::WangNdf*>(src.get());
  const double max_sigma = w->record().max_sigma;
  double a = 0.0, b = 0.0;
  ASSERT_EQ(src->eval({1e6 + 3.0, -2e6, max_sigma}, {0.1, 0.05}, &a), runtime::RuntimeStatus::kOk);
  ASSERT_EQ(src->eval({1e6 + 3.0, -2e6, 50.0 * max_sigma}, {0.1, 0.05}, &b), runtime::RuntimeStatus::kOk);
  EXPECT_EQ(a, b);
  EXPECT_EQ(w->coveredTiles({8.0, 8.0, 0.5}), 1);
  EXPECT_EQ(w->coveredTiles({16.0, 16.0, 0.5}), 4);
  EXPECT_EQ(w->coveredTiles({8.0, 8.0, max_sigma}), 9);
  EXPECT_LE(w->coveredTiles({3.0, 5.0, 1e9}), 9);
  double m = 0.0;
  ASSERT_EQ(src->mass({-123456.7, 98765.4, 2.0}, &m), runtime::RuntimeStatus::kOk);
  EXPECT_NEAR(m, 1.0, 0.02);
  EXPECT_EQ(src->eval({NAN, 0.0, 1.0}, {0, 0}, &a), runtime::RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(src->eval({0.0, 0.0, -1.0}, {0, 0}, &a), runtime::RuntimeStatus::kInvalidArgument);
}

TEST(WangNdf, RejectsMalformedAssets) {
  const auto& good = assetBytes(true);
  format::Reader reader;
  ASSERT_EQ(reader.openMemory(good.data(), good.size()), format::ContainerStatus::kOk);
  // A record with a bad colour count, resealed in a new container with the other sections.
  const auto rewrite = [&](uint32_t type, const std::function<void(std::vector<uint8_t>&)>& edit) {
    const std::string file = testing::processTempDir() + "bad.gbk";
    format::Writer w;
    EXPECT_EQ(w.open(file, format::AssetKind::kWangTiles, 1), format::ContainerStatus::kOk);
    for (size_t i = 0; i < reader.sections().size(); ++i) {
      const format::SectionInfo& s = reader.sections()[i];
      if (s.type == format::kSectionMetadata) continue;
      std::vector<uint8_t> bytes;
      EXPECT_EQ(reader.readSection(i, &bytes), format::ContainerStatus::kOk);
      if (s.type == type && s.key == 0) edit(bytes);
      EXPECT_EQ(w.addSection(s.type, s.key, bytes.data(), bytes.size()), format::ContainerStatus::kOk);
    }
    EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
    std::ifstream f(file, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    std::unique_ptr<runtime::NdfSource> src;
    return runtime::openNdfAssetMemory(bytes.data(), bytes.size(), &src);
  };
  EXPECT_EQ(rewrite(format::kSectionWangInfo, [](std::vector<uint8_t>& b) { b[8] = 9; }),
            runtime::RuntimeStatus::kInvalidAsset);
  EXPECT_EQ(rewrite(format::kSectionWangEdges, [](std::vector<uint8_t>& b) { b[0] = 3; }),
            runtime::RuntimeStatus::kInvalidAsset);
  EXPECT_EQ(rewrite(format::kSectionWangTexels, [](std::vector<uint8_t>& b) { b.pop_back(); }),
            runtime::RuntimeStatus::kInvalidAsset);
  EXPECT_EQ(rewrite(format::kSectionWangTileNdf, [](std::vector<uint8_t>& b) { b.resize(b.size() / 2); }),
            runtime::RuntimeStatus::kInvalidAsset);
  EXPECT_EQ(rewrite(0, [](std::vector<uint8_t>&) {}), runtime::RuntimeStatus::kOk);
}

}  // namespace
}  // namespace glintbake
