// SPDX-License-Identifier: Apache-2.0
// The streamed pyramid: geometry, section layout, determinism across thread counts.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/container.h>
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/ndf_pyramid.h>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>
#include "../temp_dir.h"

namespace glintbake::bake::ndf {
namespace {

std::string tempPath(const std::string& name) {
  return glintbake::testing::processTempDir() + "ndf_builder_" + name + ".gbk";
}

std::vector<char> readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

BakeStatus buildTo(const NormalMap& map, const PyramidOptions& o, const std::string& path, PyramidReport* rep) {
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kNdfPyramid, 3), format::ContainerStatus::kOk);
  BakeStatus s = buildNdfPyramid(map, o, w, rep);
  if (!s) return s;
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return s;
}

PyramidOptions smallOptions() {
  PyramidOptions o;
  o.splat.ndf_res = 32;
  o.stride0 = 8;
  o.sigma0 = 4;
  o.region_size = 3;  // several regions, partial ones at the edges
  return o;
}

TEST(PyramidGeometry, GridsCoverTheMapAndNest) {
  PyramidOptions o;
  o.stride0 = 16;
  LevelGeometry g0 = levelGeometry(1024, 512, o, 0, true), g2 = levelGeometry(1024, 512, o, 2, true);
  EXPECT_EQ(g0.grid_width, 64);
  EXPECT_EQ(g0.grid_height, 32);
  EXPECT_DOUBLE_EQ(g0.stride_x, 16.0);
  EXPECT_EQ(g2.grid_width, 16);
  EXPECT_DOUBLE_EQ(g2.sigma, o.sigma0 * 4);
  // A map that is not a multiple of the stride: the stride stretches so the grid stays periodic.
  LevelGeometry odd = levelGeometry(100, 100, o, 0, true);
  EXPECT_EQ(odd.grid_width, 6);
  EXPECT_DOUBLE_EQ(odd.stride_x * odd.grid_width, 100.0);
  EXPECT_EQ(levelGeometry(100, 100, o, 10, true).grid_width, 1);
}

TEST(PyramidBuilder, RejectsBadOptions) {
  PyramidOptions o = smallOptions();
  o.stride0 = 0;
  EXPECT_FALSE(validatePyramidOptions(o).ok());
  o = smallOptions();
  o.splat.ndf_res = 1;
  EXPECT_FALSE(validatePyramidOptions(o).ok());
  o = smallOptions();
  o.converge_mse = -1;
  EXPECT_FALSE(validatePyramidOptions(o).ok());
}

TEST(PyramidBuilder, WritesLevelsAndChunksThatMatchTheSplat) {
  MapParams mp;
  mp.size = 40;
  const NormalMap map = generateMap(MapKind::kBeckmann, mp);
  PyramidOptions o = smallOptions();
  o.levels = 3;
  const std::string path = tempPath("layout");
  PyramidReport rep;
  ASSERT_TRUE(buildTo(map, o, path, &rep).ok());
  ASSERT_EQ(rep.levels.size(), 3u);
  EXPECT_EQ(rep.stop_reason, "levels");

  format::Reader r;
  ASSERT_EQ(r.open(path), format::ContainerStatus::kOk);
  EXPECT_EQ(r.kind(), format::AssetKind::kNdfPyramid);
  for (int l = 0; l < 3; ++l) {
    const int idx = r.find(format::kSectionNdfLevel, uint64_t(l));
    ASSERT_GE(idx, 0);
    std::vector<uint8_t> bytes;
    ASSERT_EQ(r.readSection(size_t(idx), &bytes), format::ContainerStatus::kOk);
    ASSERT_EQ(bytes.size(), sizeof(runtime::NdfLevelRecord));
    runtime::NdfLevelRecord rec;
    std::memcpy(&rec, bytes.data(), sizeof(rec));
    const LevelGeometry g = levelGeometry(40, 40, o, l, true);
    EXPECT_EQ(int(rec.grid_width), g.grid_width);
    EXPECT_DOUBLE_EQ(rec.sigma_texels, 4.0 * (1 << l));
    EXPECT_DOUBLE_EQ(rec.origin_x, 0.5 * rec.stride_x);
    EXPECT_EQ(int(rec.regions_x * rec.regions_y), g.regions_x * g.regions_y);
  }
  // Level 0 has 5x5 centres in 3x3-centre regions: region 3 = (rx 1, ry 1) holds centres 3..4 x 3..4.
  const int idx = r.find(format::kSectionNdfChunk, uint64_t(3));
  ASSERT_GE(idx, 0);
  std::vector<uint8_t> chunk;
  ASSERT_EQ(r.readSection(size_t(idx), &chunk), format::ContainerStatus::kOk);
  format::ImageSectionHeader h;
  std::memcpy(&h, chunk.data(), sizeof(h));
  EXPECT_EQ(h.magic, format::ImageSectionHeader().magic);
  EXPECT_EQ(h.width, 32u);
  EXPECT_EQ(h.layers, 4u);
  // Layer 1 = centre (4, 3) at ((4 + 0.5) * 8, (3 + 0.5) * 8).
  Result<FlakeSet> flakes = buildFlakes(map, 1);
  ASSERT_TRUE(flakes.ok());
  Splatter sp(flakes.value(), o.splat);
  std::vector<float> expect(32 * 32), stored(32 * 32);
  const LevelGeometry g0 = levelGeometry(40, 40, o, 0, true);
  const FootprintPartition part =
      footprintPartition(flakes.value(), g0.sigma, g0.grid_width, g0.stride_x, g0.grid_height, g0.stride_y);
  EXPECT_FALSE(part.empty());  // stride 8 = 2 sigma on a repeating map
  sp.image(36.0, 28.0, 4.0, expect.data(), &part);
  std::memcpy(stored.data(), chunk.data() + sizeof(h) + 32 * 32 * 4, 32 * 32 * 4);
  EXPECT_EQ(stored, expect);
  std::remove(path.c_str());
}

// The partition factors make a level's Gaussian footprints sum to one at every flake, so the mean
// of the level's images is the whole map's NDF (every texel weighed alike), which the Gaussian
// footprints at stride 2 sigma miss by their ripple.
TEST(PyramidBuilder, PartitionOfUnityMakesTheLevelMeanTheWholeMap) {
  MapParams mp;
  mp.size = 40;
  mp.seed = 3;
  const NormalMap map = generateMap(MapKind::kFlakes, mp);
  Result<FlakeSet> flakes = buildFlakes(map, 1);
  ASSERT_TRUE(flakes.ok());
  const FlakeSet& f = flakes.value();
  const double sigma = 4.0, stride = 8.0;
  const int n = 5;
  const FootprintPartition part = footprintPartition(f, sigma, n, stride, n, stride);
  ASSERT_EQ(part.x.size(), size_t(f.grid_width));
  ASSERT_EQ(part.y.size(), size_t(f.grid_height));
  // Sum over the centres (and their periodic images) of the normalised Gaussian weight times the
  // factor, per axis: 1 / stride at every flake.
  const double var = f.sigma_h * f.sigma_h + sigma * sigma;
  for (int g = 0; g < f.grid_width; ++g) {
    const double u = f.positionX(g);
    double sum = 0.0;
    for (int k = -20; k < 20 + n; ++k) {
      const double d = u - (k + 0.5) * stride;
      sum += std::exp(-0.5 * d * d / var) / std::sqrt(kTwoPi * var);
    }
    EXPECT_NEAR(sum * part.x[size_t(g)] * stride, 1.0, 1e-12) << g;
  }
  SplatParams sp_params;
  sp_params.ndf_res = 32;
  Splatter sp(f, sp_params);
  const size_t bins = 32 * 32;
  std::vector<double> mean_pu(bins, 0.0), mean_gauss(bins, 0.0);
  std::vector<float> img(bins);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      sp.image((i + 0.5) * stride, (j + 0.5) * stride, sigma, img.data(), &part);
      for (size_t b = 0; b < bins; ++b) mean_pu[b] += img[b] / (n * n);
      sp.image((i + 0.5) * stride, (j + 0.5) * stride, sigma, img.data());
      for (size_t b = 0; b < bins; ++b) mean_gauss[b] += img[b] / (n * n);
    }
  }
  // The whole map's NDF: a footprint three map widths wide, whose periodic sum is flat to 1e-70.
  std::vector<float> whole(bins);
  sp.image(20.0, 20.0, 120.0, whole.data());
  auto relL1 = [&](const std::vector<double>& a) {
    double num = 0.0, den = 0.0;
    for (size_t b = 0; b < bins; ++b) {
      num += std::fabs(a[b] - whole[b]);
      den += whole[b];
    }
    return num / den;
  };
  const double e_pu = relL1(mean_pu), e_gauss = relL1(mean_gauss);
  std::printf("[ measured ] level mean against the whole map: partition %.2e, Gaussian %.2e\n", e_pu, e_gauss);
  // What is left: the footprints' truncation at 4 sigma (a disk, not separable) and the lobes'
  // shift with their offset from the centre, which the whole map's footprint does not have.
  EXPECT_LT(e_pu, 5e-4);
  EXPECT_GT(e_gauss, 5.0 * e_pu);
  // Clamped maps and single-centre axes are left alone; so is a stride far above the footprint.
  EXPECT_TRUE(footprintPartition(f, sigma, 1, 40.0, 1, 40.0).empty());
  EXPECT_TRUE(footprintPartition(f, 2.0, n, stride, n, stride).empty());
  NormalMap clamped = map;
  clamped.wrap = Wrap::kClamp;
  Result<FlakeSet> cf = buildFlakes(clamped, 1);
  ASSERT_TRUE(cf.ok());
  EXPECT_TRUE(footprintPartition(cf.value(), sigma, n, stride, n, stride).empty());
}

TEST(PyramidGeometry, PeriodicAxesKeepTwoCentresUntilTheFootprintIsFlat) {
  PyramidOptions o;  // stride 16, sigma 8
  // 37 x 23: level 0 rounds to 2 x 1 centres, but one centre along 23 texels at sigma 8 (0.35 of
  // the period) cannot mix wider footprints, so a repeating map keeps two there.
  const LevelGeometry clamp0 = levelGeometry(37, 23, o, 0, false), rep0 = levelGeometry(37, 23, o, 0, true);
  EXPECT_EQ(clamp0.grid_width, 2);
  EXPECT_EQ(clamp0.grid_height, 1);
  EXPECT_EQ(rep0.grid_width, 2);
  EXPECT_EQ(rep0.grid_height, 2);
  EXPECT_DOUBLE_EQ(rep0.stride_y, 11.5);
  // Level 1 (sigma 16): flat along 23 texels (16 >= 0.62 x 23), not along 37.
  const LevelGeometry rep1 = levelGeometry(37, 23, o, 1, true);
  EXPECT_EQ(rep1.grid_width, 2);
  EXPECT_EQ(rep1.grid_height, 1);
  const LevelGeometry rep2 = levelGeometry(37, 23, o, 2, true);
  EXPECT_EQ(rep2.grid_width * rep2.grid_height, 1);
  // Large maps are unchanged.
  EXPECT_EQ(levelGeometry(1024, 1024, o, 4, true).grid_width, levelGeometry(1024, 1024, o, 4, false).grid_width);
}

TEST(PyramidBuilder, SmallRepeatingMapsAnswerWideFootprintsWithTheWholeMap) {
  // A 20 x 13 repeating map: the pyramid of every automatic level count must give a footprint
  // far wider than the map the whole map's NDF (what the footprint sees, exactly, on a periodic
  // map), and footprints of a few times the map's size nearly that.
  MapParams mp;
  mp.size = 40;
  mp.seed = 5;
  const NormalMap big = generateMap(MapKind::kFlakes, mp);
  NormalMap map;
  map.width = 20;
  map.height = 13;
  map.wrap = Wrap::kRepeat;
  for (int y = 0; y < map.height; ++y) {
    const float* row = big.normals.data() + size_t(y) * size_t(big.width) * 3;
    map.normals.insert(map.normals.end(), row, row + size_t(map.width) * 3);
  }
  PyramidOptions o = smallOptions();  // R 32, stride 8, sigma 4
  const std::string path = tempPath("small_periodic");
  PyramidReport rep;
  ASSERT_TRUE(buildTo(map, o, path, &rep).ok());
  runtime::NdfPyramid pyr;
  ASSERT_EQ(pyr.open(path.c_str()), runtime::RuntimeStatus::kOk);

  Result<FlakeSet> flakes = buildFlakes(map, 1);
  ASSERT_TRUE(flakes.ok());
  Splatter sp(flakes.value(), o.splat);
  const size_t bins = 32 * 32;
  std::vector<float> whole(bins), got(bins);
  sp.image(10.0, 6.5, 60.0, whole.data());  // 3 map widths: flat to 1e-70
  auto relL1 = [&](const std::vector<float>& a) {
    double num = 0.0, den = 0.0;
    for (size_t b = 0; b < bins; ++b) {
      num += std::fabs(double(a[b]) - double(whole[b]));
      den += double(whole[b]);
    }
    return num / den;
  };
  for (double sigma : {1000.0, 40.0, 20.0}) {
    for (double x : {0.0, 7.3}) {
      ASSERT_EQ(pyr.image(runtime::Footprint{x, 4.1, sigma}, got.data(), bins), runtime::RuntimeStatus::kOk);
      const double e = relL1(got);
      std::printf("[ measured ] sigma %g at x %g: relative L1 against the whole map %.2e\n", sigma, x, e);
      EXPECT_LT(e, sigma >= 40.0 ? 4e-3 : 1.5e-2) << sigma << " " << x;
    }
  }
  std::remove(path.c_str());
}

TEST(PyramidBuilder, IdenticalBytesForEveryThreadCount) {
  MapParams mp;
  mp.size = 48;
  const NormalMap map = generateMap(MapKind::kFlakes, mp);
  PyramidOptions o = smallOptions();  // automatic level count
  const std::string p1 = tempPath("j1"), p2 = tempPath("j2");
  PyramidReport r1, r2;
  tbb::task_arena one(1), two(2);
  one.execute([&] { ASSERT_TRUE(buildTo(map, o, p1, &r1).ok()); });
  two.execute([&] { ASSERT_TRUE(buildTo(map, o, p2, &r2).ok()); });
  EXPECT_FALSE(r1.stop_reason.empty());
  EXPECT_EQ(r1.levels.size(), r2.levels.size());
  EXPECT_EQ(readAll(p1), readAll(p2));
  std::printf("[ measured ] auto levels: %zu, stop %s, top-level MSE %.3g\n", r1.levels.size(), r1.stop_reason.c_str(),
              r1.levels.back().mse_vs_previous);
  std::remove(p1.c_str());
  std::remove(p2.c_str());
}

TEST(PyramidBuilder, SplitFootprintsAreDeterministicAndMatchTheSplat) {
  // sigma 75 on rate 1: about 290k flakes per footprint, above the split threshold.
  MapParams mp;
  mp.size = 32;
  const NormalMap map = generateMap(MapKind::kFlakes, mp);
  PyramidOptions o;
  o.splat.ndf_res = 16;
  o.stride0 = 16;
  o.sigma0 = 75;
  o.levels = 1;
  const std::string p1 = tempPath("split1"), p2 = tempPath("split2");
  tbb::task_arena one(1), two(2);
  one.execute([&] { ASSERT_TRUE(buildTo(map, o, p1, nullptr).ok()); });
  two.execute([&] { ASSERT_TRUE(buildTo(map, o, p2, nullptr).ok()); });
  EXPECT_EQ(readAll(p1), readAll(p2));
  format::Reader r;
  ASSERT_EQ(r.open(p1), format::ContainerStatus::kOk);
  std::vector<uint8_t> chunk;
  ASSERT_EQ(r.readSection(size_t(r.find(format::kSectionNdfChunk, 0)), &chunk), format::ContainerStatus::kOk);
  Result<FlakeSet> flakes = buildFlakes(map, 1);
  ASSERT_TRUE(flakes.ok());
  Splatter sp(flakes.value(), o.splat);
  std::vector<float> whole(16 * 16), stored(16 * 16);
  sp.image(24.0, 8.0, 75.0, whole.data());  // centre (1, 0)
  std::memcpy(stored.data(), chunk.data() + sizeof(format::ImageSectionHeader) + 16 * 16 * 4, 16 * 16 * 4);
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < whole.size(); ++i) {
    num += std::fabs(double(stored[i]) - whole[i]);
    den += whole[i];
  }
  EXPECT_LT(num / den, 1e-6);
  std::remove(p1.c_str());
  std::remove(p2.c_str());
}

}  // namespace
}  // namespace glintbake::bake::ndf
