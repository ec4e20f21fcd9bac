// SPDX-License-Identifier: Apache-2.0
// The fast splatted NDF images against the reference evaluator and against the physical
// invariants: flat map = bin-averaged Gaussian, unit mass on wrapped maps, rotation/mirror
// equivariance.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/flakes.h>
#include <glintbake/bake/ndf/splat.h>
#include <glintbake/reference/pndf.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

namespace glintbake::bake::ndf {
namespace {

constexpr int kRes = 64;

NormalMap makeMap(MapKind kind, int size, uint64_t seed = 7) {
  MapParams p;
  p.size = size;
  p.seed = seed;
  if (kind == MapKind::kScratches) p.density = 8.0;
  return generateMap(kind, p);
}

double relativeL1(const std::vector<float>& a, const std::vector<double>& ref) {
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < ref.size(); ++i) {
    num += std::fabs(double(a[i]) - ref[i]);
    den += std::fabs(ref[i]);
  }
  return num / den;
}

double mass(const std::vector<float>& img, int res) {
  double m = 0.0;
  for (float v : img) m += v;
  return m * 4.0 / (double(res) * res);
}

class SplatVsReference : public ::testing::TestWithParam<MapKind> {};

TEST_P(SplatVsReference, MatchesBinAveragedReference) {
  const MapKind kind = GetParam();
  const NormalMap map = makeMap(kind, 64);
  Result<FlakeSet> flakes = buildFlakes(map, 1);
  ASSERT_TRUE(flakes.ok());
  const reference::FlakeSet ref_flakes = reference::buildFlakes(map, 1);
  // The integration itself, with the footprint cut at 4 std (its truncation leaves out 3.4e-4 of
  // the weight), and the default cut at 3.5 std (2.2e-3 left out).
  for (const auto& [truncation, bound] : {std::pair{4.0, 1e-3}, std::pair{3.5, 5e-3}}) {
    SplatParams params;
    params.ndf_res = kRes;
    params.footprint_truncation = truncation;
    Splatter splatter(flakes.value(), params);
    std::mt19937_64 rng(1234 + int(kind));
    std::uniform_real_distribution<double> pos(0.0, 64.0);
    std::vector<float> img(size_t(kRes) * kRes);
    double worst = 0.0;
    for (double sigma : {0.7, 2.0, 6.0}) {
      for (int k = 0; k < 2; ++k) {
        const double x = pos(rng), y = pos(rng);
        splatter.image(x, y, sigma, img.data());
        reference::Footprint fp;
        fp.x = x;
        fp.y = y;
        fp.sigma = sigma;
        const std::vector<double> ref = reference::binAveragedImage(ref_flakes, fp, params.sigma_r, kRes);
        const double err = relativeL1(img, ref);
        worst = std::max(worst, err);
        EXPECT_LT(err, bound) << mapKindString(kind) << " at (" << x << ", " << y << ") sigma " << sigma
                              << " truncation " << truncation;
      }
    }
    std::printf("[ measured ] %s, footprints cut at %.1f std: worst relative L1 splat vs reference %.3g\n",
                mapKindString(kind), truncation, worst);
  }
}

INSTANTIATE_TEST_SUITE_P(AllKinds, SplatVsReference,
                         ::testing::Values(MapKind::kFlat, MapKind::kBeckmann, MapKind::kBrushed, MapKind::kScratches,
                                           MapKind::kFlakes),
                         [](const ::testing::TestParamInfo<MapKind>& param_info) {
                           return mapKindString(param_info.param);
                         });

// A footprint wider than a repeating map sees each flake at several periodic images; the splat
// folds them into one lobe per flake (Splatter::accumulate). On sharp flakes of a 60-degree cone,
// whose Jacobians at the cell edges shift the images' lobes the most, and on a Beckmann map, the
// folded images stay within 4.5e-4 of the reference, which sums every image's own lobe.
TEST(Splat, FootprintsWiderThanTheMapFoldEachFlakesImages) {
  MapParams p;
  p.size = 24;
  p.seed = 3;
  p.cone_degrees = 60.0;
  p.cell = 3.0;
  const NormalMap sharp = generateMap(MapKind::kFlakes, p);
  const NormalMap beckmann = makeMap(MapKind::kBeckmann, 24);
  for (const NormalMap* map : {&sharp, &beckmann}) {
    Result<FlakeSet> flakes = buildFlakes(*map, 1);
    ASSERT_TRUE(flakes.ok());
    const reference::FlakeSet ref_flakes = reference::buildFlakes(*map, 1);
    SplatParams params;
    params.ndf_res = kRes;
    params.footprint_truncation = 4.0;  // the fold's error alone, without the default cut's 2e-3
    Splatter splatter(flakes.value(), params);
    std::vector<float> img(size_t(kRes) * kRes);
    double worst = 0.0;
    for (double sigma : {5.0, 9.0, 20.0}) {
      const double x = 7.3, y = 15.9;
      const int64_t lobes = splatter.image(x, y, sigma, img.data());
      // Fewer lobes than the images within the truncation radius: the images were folded.
      EXPECT_LT(double(lobes), 0.8 * splatter.flakesPerImage(sigma)) << "sigma " << sigma;
      reference::Footprint fp;
      fp.x = x;
      fp.y = y;
      fp.sigma = sigma;
      const std::vector<double> ref = reference::binAveragedImage(ref_flakes, fp, params.sigma_r, kRes);
      // The same mass (below 1 where the cone's lobes reach past the unit disk).
      double ref_mass = 0.0;
      for (double v : ref) ref_mass += v;
      EXPECT_NEAR(mass(img, kRes), ref_mass * 4.0 / (double(kRes) * kRes), 1e-3) << "sigma " << sigma;
      const double err = relativeL1(img, ref);
      worst = std::max(worst, err);
      // 3.5e-4 (sharp) and 4.0e-4 (Beckmann) measured; without the images' mean spread in the
      // folded lobe's covariance the sharp map gives 5.1e-4, with the nearest image's mean instead
      // of the weighted mean 0.12.
      EXPECT_LT(err, 4.5e-4) << "sigma " << sigma;
    }
    std::printf("[ measured ] worst relative L1 of folded images vs reference %.3g\n", worst);
  }
}

TEST(Splat, FlatMapIsBinAveragedGaussian) {
  const NormalMap map = makeMap(MapKind::kFlat, 32);
  Result<FlakeSet> flakes = buildFlakes(map, 1);
  ASSERT_TRUE(flakes.ok());
  for (int res : {64, 128}) {
    SplatParams params;
    params.ndf_res = res;
    Splatter splatter(flakes.value(), params);
    std::vector<float> img(size_t(res) * res);
    splatter.image(10.3, 20.9, 3.0, img.data());
    // Exact bin average of N(0, sigma_r^2 I): product of erf differences.
    const double h = 2.0 / res, sr = params.sigma_r;
    auto cdf = [&](double v) { return 0.5 * std::erfc(-v / (sr * std::sqrt(2.0))); };
    double num = 0.0, den = 0.0;
    for (int j = 0; j < res; ++j) {
      for (int i = 0; i < res; ++i) {
        const double px = cdf(-1 + (i + 1) * h) - cdf(-1 + i * h);
        const double py = cdf(1 - j * h) - cdf(1 - (j + 1) * h);
        const double expected = px * py / (h * h);
        num += std::fabs(img[size_t(j) * res + i] - expected);
        den += expected;
      }
    }
    EXPECT_LT(num / den, 1e-3) << "R = " << res;
    EXPECT_NEAR(mass(img, res), 1.0, 1e-3);
  }
}

TEST(Splat, WrappedImagesIntegrateToOne) {
  for (MapKind kind : {MapKind::kBeckmann, MapKind::kBrushed, MapKind::kFlakes, MapKind::kScratches}) {
    const NormalMap map = makeMap(kind, 32);
    Result<FlakeSet> flakes = buildFlakes(map, 1);
    ASSERT_TRUE(flakes.ok());
    SplatParams params;
    params.ndf_res = kRes;
    Splatter splatter(flakes.value(), params);
    std::vector<float> img(size_t(kRes) * kRes);
    // Includes footprints wider than the map (several periodic images of each flake).
    for (double sigma : {1.0, 4.0, 20.0}) {
      splatter.image(0.25, 31.5, sigma, img.data());
      EXPECT_NEAR(mass(img, kRes), 1.0, 1e-3) << mapKindString(kind) << " sigma " << sigma;
    }
  }
}

// Rotates a map by 90 degrees counter-clockwise (as seen with y up): texel (c, r) moves to
// (r, W - 1 - c) and normals rotate (x, y) -> (-y, x).
NormalMap rotate90(const NormalMap& m) {
  NormalMap out = m;
  out.width = m.height;
  out.height = m.width;
  for (int r = 0; r < m.height; ++r) {
    for (int c = 0; c < m.width; ++c) {
      const float* n = m.at(c, r);
      float* o = out.at(r, m.width - 1 - c);
      o[0] = -n[1];
      o[1] = n[0];
      o[2] = n[2];
    }
  }
  return out;
}

NormalMap mirrorX(const NormalMap& m) {
  NormalMap out = m;
  for (int r = 0; r < m.height; ++r) {
    for (int c = 0; c < m.width; ++c) {
      const float* n = m.at(c, r);
      float* o = out.at(m.width - 1 - c, r);
      o[0] = -n[0];
      o[1] = n[1];
      o[2] = n[2];
    }
  }
  return out;
}

double compareL1(const std::vector<float>& a, const std::vector<float>& b) {
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    num += std::fabs(double(a[i]) - double(b[i]));
    den += std::fabs(double(b[i]));
  }
  return num / den;
}

TEST(Splat, RotatedAndMirroredMapsRotateAndMirrorTheImage) {
  for (MapKind kind : {MapKind::kBrushed, MapKind::kScratches}) {
    MapParams p;
    p.size = 48;
    p.seed = 3;
    NormalMap map = generateMap(kind, p);
    map.wrap = Wrap::kClamp;  // also exercises the edges without periodic images
    const NormalMap rotated = rotate90(map), mirrored = mirrorX(map);
    Result<FlakeSet> f0 = buildFlakes(map, 1), f1 = buildFlakes(rotated, 1), f2 = buildFlakes(mirrored, 1);
    ASSERT_TRUE(f0.ok() && f1.ok() && f2.ok());
    SplatParams params;
    params.ndf_res = kRes;
    Splatter s0(f0.value(), params), s1(f1.value(), params), s2(f2.value(), params);
    const double x = 13.7, y = 30.2, sigma = 3.0;
    std::vector<float> a(size_t(kRes) * kRes), b(a.size()), c(a.size()), expect_rot(a.size()), expect_mir(a.size());
    s0.image(x, y, sigma, a.data());
    s1.image(y, map.width - x, sigma, b.data());
    s2.image(map.width - x, y, sigma, c.data());
    for (int j = 0; j < kRes; ++j) {
      for (int i = 0; i < kRes; ++i) {
        const float v = a[size_t(j) * kRes + i];
        expect_rot[size_t(kRes - 1 - i) * kRes + j] = v;    // s -> (-s_y, s_x)
        expect_mir[size_t(j) * kRes + (kRes - 1 - i)] = v;  // s -> (-s_x, s_y)
      }
    }
    EXPECT_LT(compareL1(b, expect_rot), 1e-3) << mapKindString(kind);
    EXPECT_LT(compareL1(c, expect_mir), 1e-4) << mapKindString(kind);
  }
}

TEST(Splat, DeterministicAndIndependentOfHistory) {
  const NormalMap map = makeMap(MapKind::kBeckmann, 32);
  Result<FlakeSet> flakes = buildFlakes(map, 2);
  ASSERT_TRUE(flakes.ok());
  SplatParams params;
  params.ndf_res = 32;
  Splatter a(flakes.value(), params), b(flakes.value(), params);
  std::vector<float> x(32 * 32), y(32 * 32), z(32 * 32);
  a.image(5.0, 6.0, 2.0, x.data());
  a.image(20.0, 1.0, 7.0, z.data());  // a different image in between must leave no trace
  a.image(5.0, 6.0, 2.0, y.data());
  b.image(5.0, 6.0, 2.0, z.data());
  EXPECT_EQ(x, y);
  EXPECT_EQ(x, z);
}

TEST(Flakes, RateSubSamplesFollowTheFlakeModel) {
  const NormalMap map = makeMap(MapKind::kBeckmann, 16);
  Result<FlakeSet> f = buildFlakes(map, 3);
  ASSERT_TRUE(f.ok());
  const reference::FlakeSet ref = reference::buildFlakes(map, 3);
  EXPECT_EQ(f.value().grid_width, 48);
  EXPECT_NEAR(f.value().sigma_h, (1.0 / 3.0) * 1.5 / std::sqrt(12.0), 1e-12);
  // Position and normal of a sub-sample against the interpolant.
  double nx, ny;
  interpolateNormal(map, f.value().positionX(7), f.value().positionY(11), &nx, &ny);
  EXPECT_NEAR(f.value().flake(7, 11)[0], nx, 1e-6);
  EXPECT_NEAR(f.value().flake(7, 11)[1], ny, 1e-6);
  EXPECT_FALSE(buildFlakes(map, 0).ok());
  EXPECT_FALSE(buildFlakes(map, kMaxFlakeRate + 1).ok());
}

}  // namespace
}  // namespace glintbake::bake::ndf
