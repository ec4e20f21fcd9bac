// SPDX-License-Identifier: Apache-2.0
// Procedural maps: determinism, the statistics each kind promises, and parameter validation.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/format/numbers.h>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <string>

namespace glintbake::bake {
namespace {

MapParams params(int size, uint64_t seed) {
  MapParams p;
  p.size = size;
  p.seed = seed;
  return p;
}

void expectUnitUpperHemisphere(const NormalMap& map) {
  ASSERT_EQ(map.normals.size(), size_t(map.width) * map.height * 3);
  EXPECT_EQ(map.wrap, Wrap::kRepeat);
  for (size_t i = 0; i < map.normals.size(); i += 3) {
    const double x = map.normals[i], y = map.normals[i + 1], z = map.normals[i + 2];
    ASSERT_NEAR(std::sqrt(x * x + y * y + z * z), 1.0, 1e-5) << "texel " << i / 3;
    ASSERT_GT(z, 0.0) << "texel " << i / 3;
  }
}

TEST(Mapgen, KindNamesRoundTrip) {
  for (MapKind k : {MapKind::kFlat, MapKind::kBeckmann, MapKind::kBrushed, MapKind::kScratches, MapKind::kFlakes}) {
    MapKind parsed = MapKind::kFlat;
    ASSERT_TRUE(mapKindFromString(mapKindString(k), &parsed));
    EXPECT_EQ(parsed, k);
    EXPECT_NE(mapKindList().find(mapKindString(k)), std::string::npos);
  }
  MapKind unused;
  EXPECT_FALSE(mapKindFromString("Beckmann", &unused));
  EXPECT_FALSE(mapKindFromString("", &unused));
}

TEST(Mapgen, FlatIsFlat) {
  const NormalMap map = generateMap(MapKind::kFlat, params(17, 3));
  EXPECT_EQ(map.width, 17);
  EXPECT_EQ(map.height, 17);
  for (size_t i = 0; i < map.normals.size(); i += 3) {
    EXPECT_EQ(map.normals[i], 0.0f);
    EXPECT_EQ(map.normals[i + 1], 0.0f);
    EXPECT_EQ(map.normals[i + 2], 1.0f);
  }
  const MapStatistics s = measureMap(map);
  EXPECT_EQ(s.slope_std[0], 0.0);
  EXPECT_EQ(s.max_angle_degrees, 0.0);
}

TEST(Mapgen, DeterministicBySeedAndThreadCount) {
  for (MapKind kind : {MapKind::kBeckmann, MapKind::kBrushed, MapKind::kScratches, MapKind::kFlakes}) {
    MapParams p = params(96, 42);
    p.density = 8.0;
    const NormalMap a = generateMap(kind, p);
    NormalMap single;
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      single = generateMap(kind, p);
    }
    EXPECT_EQ(a.normals, single.normals) << mapKindString(kind);
    EXPECT_EQ(a.normals, generateMap(kind, p).normals) << mapKindString(kind);
    p.seed = 43;
    EXPECT_NE(a.normals, generateMap(kind, p).normals) << mapKindString(kind);
  }
}

TEST(Mapgen, BeckmannSlopeStdMatchesAlpha) {
  for (double alpha : {0.1, 0.3, 0.6}) {
    for (uint64_t seed : {1u, 2u}) {
      MapParams p = params(256, seed);
      p.alpha = alpha;
      const NormalMap map = generateMap(MapKind::kBeckmann, p);
      expectUnitUpperHemisphere(map);
      const MapStatistics s = measureMap(map);
      const double target = alpha / std::sqrt(2.0);
      EXPECT_NEAR(s.slope_std[0], target, 0.1 * target) << "alpha " << alpha << " seed " << seed;
      EXPECT_NEAR(s.slope_std[1], target, 0.1 * target) << "alpha " << alpha << " seed " << seed;
      EXPECT_NEAR(s.slope_mean[0], 0.0, 0.1 * target);
      EXPECT_NEAR(s.slope_mean[1], 0.0, 0.1 * target);
    }
  }
}

TEST(Mapgen, BeckmannIsTileable) {
  // A smooth periodic surface: the normal difference across the wrap seam is no larger than
  // between interior neighbours.
  const NormalMap map = generateMap(MapKind::kBeckmann, params(128, 9));
  auto diff = [&](int x0, int y0, int x1, int y1) {
    double d = 0.0;
    for (int k = 0; k < 3; ++k) d = std::max(d, double(std::abs(map.fetch(x0, y0)[k] - map.fetch(x1, y1)[k])));
    return d;
  };
  double interior = 0.0, seam = 0.0;
  for (int i = 0; i < 128; ++i) {
    interior = std::max({interior, diff(63, i, 64, i), diff(i, 63, i, 64)});
    seam = std::max({seam, diff(127, i, 128, i), diff(i, 127, i, 128)});
  }
  EXPECT_LT(seam, 2.0 * interior + 1e-6);
}

TEST(Mapgen, BrushedIsAnisotropic) {
  MapParams p = params(256, 5);
  p.alpha_x = 0.05;
  p.alpha_y = 0.4;
  const NormalMap map = generateMap(MapKind::kBrushed, p);
  expectUnitUpperHemisphere(map);
  const MapStatistics s = measureMap(map);
  EXPECT_NEAR(s.slope_std[0], 0.05 / std::sqrt(2.0), 0.15 * 0.05 / std::sqrt(2.0));
  EXPECT_NEAR(s.slope_std[1], 0.4 / std::sqrt(2.0), 0.15 * 0.4 / std::sqrt(2.0));
  // Grooves run along x: neighbours along a row are far more alike than along a column.
  double along = 0.0, across = 0.0;
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) {
      along += std::abs(map.fetch(x + 1, y)[1] - map.fetch(x, y)[1]);
      across += std::abs(map.fetch(x, y + 1)[1] - map.fetch(x, y)[1]);
    }
  }
  EXPECT_LT(along, 0.5 * across);
}

TEST(Mapgen, FlakesLieWithinTheConeAndFormCells) {
  MapParams p = params(128, 11);
  p.cone_degrees = 12.0;
  p.cell = 8.0;
  const NormalMap map = generateMap(MapKind::kFlakes, p);
  expectUnitUpperHemisphere(map);
  const MapStatistics s = measureMap(map);
  EXPECT_LE(s.max_angle_degrees, 12.0 + 1e-3);
  EXPECT_GT(s.max_angle_degrees, 6.0);
  // Uniform in solid angle over the cap: E[cos theta] = (1 + cos(cone)) / 2.
  EXPECT_NEAR(s.mean_normal[2], 0.5 * (1.0 + std::cos(12.0 * kPi / 180.0)), 2e-3);
  // Piecewise constant: most neighbours share their cell (boundary length ~ 2 / cell per texel).
  int64_t equal = 0, total = 0;
  for (int y = 0; y < 128; ++y) {
    for (int x = 0; x < 128; ++x) {
      ++total;
      if (map.fetch(x + 1, y)[0] == map.fetch(x, y)[0] && map.fetch(x + 1, y)[1] == map.fetch(x, y)[1]) ++equal;
    }
  }
  EXPECT_GT(double(equal) / double(total), 0.75);
  EXPECT_LT(double(equal) / double(total), 0.97);
}

TEST(Mapgen, ScratchesTiltOnlyInsideGrooves) {
  MapParams p = params(128, 4);
  p.density = 3.0;
  p.width = 3.0;
  p.scratch_slope = 0.5;
  const NormalMap map = generateMap(MapKind::kScratches, p);
  expectUnitUpperHemisphere(map);
  int64_t flat = 0, tilted = 0;
  for (size_t i = 2; i < map.normals.size(); i += 3) (map.normals[i] == 1.0f ? flat : tilted)++;
  // About 49 grooves of mean length 0.3 * 128 and width 3 (about 4 with the partly covered
  // texels on their edges) cover roughly 40% of the map, less where they overlap.
  const double fraction = double(tilted) / double(flat + tilted);
  EXPECT_GT(fraction, 0.25);
  EXPECT_LT(fraction, 0.5);
  // A single groove wall has slope 0.5: the largest tilt is atan(0.5) unless grooves cross.
  const MapStatistics s = measureMap(map);
  EXPECT_GT(s.max_angle_degrees, 0.9 * std::atan(0.5) * 180.0 / kPi);

  MapParams none = p;
  none.density = 0.0;
  EXPECT_EQ(measureMap(generateMap(MapKind::kScratches, none)).max_angle_degrees, 0.0);
}

TEST(Mapgen, ValidationNamesTheParameter) {
  MapParams p = params(64, 1);
  p.alpha = -0.1;
  BakeStatus s = validateMapParams(MapKind::kBeckmann, p);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kBadArgument);
  EXPECT_NE(s.error().message.find("alpha"), std::string::npos);
  EXPECT_TRUE(validateMapParams(MapKind::kFlat, p).ok());  // unused parameters are not checked

  p = params(64, 1);
  p.cone_degrees = 95.0;
  EXPECT_NE(validateMapParams(MapKind::kFlakes, p).error().message.find("cone"), std::string::npos);
  p = params(64, 1);
  p.alpha_x = std::nan("");
  EXPECT_FALSE(validateMapParams(MapKind::kBrushed, p).ok());
  p = params(0, 1);
  EXPECT_FALSE(validateMapParams(MapKind::kFlat, p).ok());
  p = params(64, 1);
  p.width = 40.0;
  EXPECT_FALSE(validateMapParams(MapKind::kScratches, p).ok());
  p = params(64, 1);
  p.cell = 100.0;
  EXPECT_FALSE(validateMapParams(MapKind::kFlakes, p).ok());
  // Defaults work at every size.
  for (int size : {1, 2, 5, 64}) {
    for (MapKind k : {MapKind::kFlat, MapKind::kBeckmann, MapKind::kBrushed, MapKind::kFlakes}) {
      MapParams d = params(size, 1);
      ASSERT_TRUE(validateMapParams(k, d).ok()) << mapKindString(k) << " " << size;
      expectUnitUpperHemisphere(generateMap(k, d));
    }
  }
}

}  // namespace
}  // namespace glintbake::bake
