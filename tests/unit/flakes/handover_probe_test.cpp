// SPDX-License-Identifier: Apache-2.0
// The probe that decides where a compressed pyramid's first exact level takes over from the
// clustered lobes (bake::ndf::probeExactLevelHandover): on sharp flakes a few dozen glints
// dominate a footprint, and the lobes are far closer to the exact flakes than the blend of the
// level's centres; over a square of noise a footprint holds many similar texels, and over a strip
// of it a few texels wide the blend spreads along the strip only: the blend is faithful and the
// pyramid, the cheaper path, answers.
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/texel_source.h>

#include "flakes_asset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace glintbake {
namespace {

bake::NormalMap noiseMap(int size, double alpha, double cell) { return testing::beckmannMap(size, alpha, cell, 5); }

// The first `columns` columns of a map, as a map of their own (repeating).
bake::NormalMap columns(const bake::NormalMap& map, int count) {
  bake::NormalMap out = map;
  out.width = count;
  out.normals.assign(size_t(count) * size_t(map.height) * 3, 0.0f);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < count; ++x) std::memcpy(out.at(x, y), map.at(x, y), 3 * sizeof(float));
  return out;
}

// The pyramid's levels from `first` up (the default geometry of the map), as the probe takes them.
std::vector<bake::ndf::PyramidLevelShape> levelsFrom(const bake::NormalMap& map, int first, int count) {
  const bake::ndf::PyramidOptions o;
  std::vector<bake::ndf::PyramidLevelShape> out;
  for (int l = first; l < first + count; ++l) {
    const bake::ndf::LevelGeometry g = bake::ndf::levelGeometry(map.width, map.height, o, l, true);
    out.push_back({g.sigma, g.grid_width, g.grid_height});
  }
  return out;
}

bake::ndf::HandoverProbe probe(const bake::NormalMap& map, const std::vector<bake::ndf::PyramidLevelShape>& levels) {
  const runtime::InterleavedTexels texels(map.width, map.height, map.wrap == bake::Wrap::kRepeat, map.normals.data(),
                                          3);
  return bake::ndf::probeExactLevelHandover(texels, 1, reference::kDefaultSigmaR, bake::ndf::kDefaultLobesPerTile,
                                            levels.data(), int(levels.size()), std::sqrt(2.0) * levels[0].sigma);
}

TEST(HandoverProbe, LobesAreCloserOnSparseFlakes) {
  const bake::NormalMap flakes = testing::flakesMap(256, 12.0, 15.0, 5);
  const bake::ndf::HandoverProbe p = probe(flakes, levelsFrom(flakes, 1, 3));
  ASSERT_TRUE(p.ran);
  EXPECT_DOUBLE_EQ(p.sigma, 16.0 * std::sqrt(2.0));
  std::printf("[ figures  ] flakes: blend %.3f, lobes %.3f, baseline %.3f\n", p.blend_error, p.lobes_error, p.baseline);
  EXPECT_TRUE(p.lobesAnswer());
  EXPECT_GT(p.blend_error, 2.0 * p.lobes_error);
  EXPECT_GT(p.blend_error, bake::ndf::kHandoverBlendMaxError);
}

TEST(HandoverProbe, ThePyramidAnswersNoiseOverASquareAndOverAStrip) {
  const bake::NormalMap bumps = noiseMap(256, 0.3, 1.0);
  const bake::ndf::HandoverProbe p = probe(bumps, levelsFrom(bumps, 1, 3));
  ASSERT_TRUE(p.ran);
  std::printf("[ figures  ] square: blend %.3f, lobes %.3f, baseline %.3f\n", p.blend_error, p.lobes_error, p.baseline);
  EXPECT_FALSE(p.lobesAnswer());
  EXPECT_LT(p.blend_error, bake::ndf::kHandoverBlendMaxError);
  // A strip 5 texels wide of the same noise: a level has one centre across it, and the blend
  // spreads along the strip only (format::NdfPyramidBlend::spread), so it stays on the level probed.
  const bake::NormalMap strip = columns(noiseMap(512, 0.3, 1.0), 5);
  const bake::ndf::HandoverProbe s = probe(strip, levelsFrom(strip, 1, 3));
  ASSERT_TRUE(s.ran);
  std::printf("[ figures  ] strip: blend %.3f, lobes %.3f, baseline %.3f\n", s.blend_error, s.lobes_error, s.baseline);
  EXPECT_FALSE(s.lobesAnswer());
  EXPECT_LT(s.blend_error, bake::ndf::kHandoverBlendMaxError);
}

TEST(HandoverProbe, NothingIsProbedWhereThePyramidAnswersAlone) {
  // sqrt(2) x 16 texels is beyond the flat footprint of a 32^2 repeating map (0.62 x 32): the
  // pyramid answers there whatever the probe would say (capAtFlatFootprint).
  const bake::NormalMap small = noiseMap(32, 0.3, 1.0);
  EXPECT_FALSE(probe(small, levelsFrom(small, 1, 2)).ran);
  // No lobes, no levels, or levels out of order: nothing is probed either.
  const bake::NormalMap map = noiseMap(128, 0.3, 1.0);
  const runtime::InterleavedTexels texels(map.width, map.height, true, map.normals.data(), 3);
  std::vector<bake::ndf::PyramidLevelShape> levels = levelsFrom(map, 1, 2);
  EXPECT_FALSE(bake::ndf::probeExactLevelHandover(texels, 1, 0.005, 0, levels.data(), 2, 1.5 * levels[0].sigma).ran);
  EXPECT_FALSE(bake::ndf::probeExactLevelHandover(texels, 1, 0.005, 16, levels.data(), 0, 1.5 * levels[0].sigma).ran);
  EXPECT_FALSE(bake::ndf::probeExactLevelHandover(texels, 1, 0.005, 16, levels.data(), 2, levels[0].sigma).ran);
  std::swap(levels[0], levels[1]);
  EXPECT_FALSE(bake::ndf::probeExactLevelHandover(texels, 1, 0.005, 16, levels.data(), 2, 1.5 * levels[0].sigma).ran);
}

}  // namespace
}  // namespace glintbake
