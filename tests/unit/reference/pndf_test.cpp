// SPDX-License-Identifier: Apache-2.0
// The per-flake closed form and the point evaluation of the reference P-NDF.
#include <glintbake/format/numbers.h>
#include <glintbake/reference/pndf.h>

#include "test_maps.h"

#include <gtest/gtest.h>

#include <cmath>

namespace glintbake::reference {
namespace {

double gaussian2d(double dx, double dy, double sigma) {
  return std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma)) / (2 * kPi * sigma * sigma);
}

// The lobe formula against a direct numerical integral over u of G_P(u) G_k(u, s) (Yan et al.
// 2016: the element G_k and the footprint G_P as written in glintbake/reference/pndf.h).
TEST(ReferencePndf, ClosedFormEqualsIntegralOverPosition) {
  FlakeSet set;
  set.width = set.height = 1;
  set.rate = 1;
  set.step = 1.0;
  set.area = 1.0;
  set.sigma_h = 1.5 / std::sqrt(12.0);
  const Flake flake = {{0.5, 0.5}, {0.1, -0.2}, {0.3, -0.1, 0.2, 0.15}};
  const Footprint fp = {1.2, 0.1, 0.8};
  const double sigma_r = 0.05;
  const FlakeLobe lobe = flakeLobe(set, flake, flake.u[0], flake.u[1], fp, sigma_r);

  const double sh = set.sigma_h;
  const double c_k = set.area / (4 * kPi * kPi * sh * sh * sigma_r * sigma_r);
  const double s_points[3][2] = {{0.1, -0.2}, {0.16, -0.21}, {0.02, -0.3}};
  for (const auto& s : s_points) {
    // Trapezoid rule on a fine grid: spectrally accurate for this smooth, decaying integrand.
    const double h = 0.004;
    const int n = int(8 * sh / h);
    double integral = 0.0;
    for (int b = -n; b <= n; ++b) {
      for (int a = -n; a <= n; ++a) {
        const double du[2] = {a * h, b * h};  // u - u_k
        const double ux = flake.u[0] + du[0];
        const double uy = flake.u[1] + du[1];
        const double rx = s[0] - flake.n[0] - (flake.jacobian[0] * du[0] + flake.jacobian[1] * du[1]);
        const double ry = s[1] - flake.n[1] - (flake.jacobian[2] * du[0] + flake.jacobian[3] * du[1]);
        const double g_k = c_k * std::exp(-(du[0] * du[0] + du[1] * du[1]) / (2 * sh * sh)) *
                           std::exp(-(rx * rx + ry * ry) / (2 * sigma_r * sigma_r));
        integral += gaussian2d(ux - fp.x, uy - fp.y, fp.sigma) * g_k;
      }
    }
    integral *= h * h;
    EXPECT_NEAR(lobeDensity(lobe, s[0], s[1]), integral, 1e-8 * integral) << s[0] << "," << s[1];
  }
}

TEST(ReferencePndf, FlatMapIsTheIntrinsicGaussian) {
  const FlakeSet set = buildFlakes(testing::constantMap(16, 16, 0.0, 0.0));
  const double sigma_r = 0.005;
  for (double sigma : {1.0, 3.0, 10.0}) {
    const Footprint fp = {3.7, 12.2, sigma};
    EXPECT_NEAR(footprintWeight(set, fp), 1.0, 1e-7);
    for (double s : {0.0, 0.004, 0.011}) {
      const double expected = gaussian2d(s, -0.5 * s, sigma_r);
      EXPECT_NEAR(evalPndf(set, fp, s, -0.5 * s, sigma_r), expected, 1e-7 * expected);
    }
  }
}

TEST(ReferencePndf, SingleTiltedTexelIsAnOffsetGaussian) {
  // A 1x1 wrapped map is an infinite lattice of identical flakes with J = 0: D = W N(s; n, sigma_r^2).
  const double nx = 0.3, ny = -0.2;
  const bake::NormalMap map = testing::constantMap(1, 1, nx, ny);
  const FlakeSet set = buildFlakes(map);
  const double sigma_r = 0.01;
  const Footprint fp = {0.2, 0.9, 2.5};
  const double weight = footprintWeight(set, fp);
  EXPECT_NEAR(weight, 1.0, 1e-7);  // the truncation leaves out exp(-18) of the mass
  const double fx = map.normals[0], fy = map.normals[1];
  for (double d : {0.0, 0.007, 0.02}) {
    const double expected = weight * gaussian2d(d, 2 * d, sigma_r);
    EXPECT_NEAR(evalPndf(set, fp, fx + d, fy + 2 * d, sigma_r), expected, 1e-12 * gaussian2d(0, 0, sigma_r));
  }

  // With clamp there is a single flake: D = A N(u_k; u_Q, (sigma_h^2 + sigma^2) I) N(s; n, sigma_r^2 I).
  const FlakeSet single = buildFlakes(testing::constantMap(1, 1, nx, ny, bake::Wrap::kClamp));
  const double v = single.sigma_h * single.sigma_h + fp.sigma * fp.sigma;
  const double spatial = gaussian2d(0.5 - fp.x, 0.5 - fp.y, std::sqrt(v));
  EXPECT_NEAR(footprintWeight(single, fp), spatial, 1e-15);
  EXPECT_NEAR(evalPndf(single, fp, fx + 0.01, fy, sigma_r), spatial * gaussian2d(0.01, 0.0, sigma_r), 1e-10);
}

TEST(ReferencePndf, ClampMapHasNoFlakesOutside) {
  const FlakeSet set = buildFlakes(testing::wavyMap(8, 8, 0.3, bake::Wrap::kClamp));
  EXPECT_EQ(footprintLobes(set, {-20.0, 4.0, 2.0}, 0.005).size(), 0u);
  EXPECT_EQ(evalPndf(set, {4.0, 40.0, 2.0}, 0.0, 0.0, 0.005), 0.0);
  // At an edge about half of the footprint's mass is missing.
  EXPECT_NEAR(footprintWeight(set, {0.0, 4.0, 1.5}), 0.5, 0.02);
  // A footprint larger than the map sees the map exactly once.
  EXPECT_EQ(footprintLobes(set, {4.0, 4.0, 50.0}, 0.005).size(), 64u);
}

TEST(ReferencePndf, TruncationRadiusIsSixSigma) {
  const FlakeSet set = buildFlakes(testing::wavyMap(64, 64));
  const double sigma = 3.0;
  const double radius = kTruncationSigmas * std::sqrt(set.sigma_h * set.sigma_h + sigma * sigma);
  const std::vector<FlakeLobe> lobes = footprintLobes(set, {32.0, 32.0, sigma}, 0.005);
  // Lattice points of the unit grid (offset by 0.5) in the disk of that radius around (32, 32).
  size_t expected = 0;
  for (int r = 0; r < 64; ++r) {
    for (int c = 0; c < 64; ++c) {
      const double dx = c + 0.5 - 32.0, dy = r + 0.5 - 32.0;
      if (dx * dx + dy * dy <= radius * radius) ++expected;
    }
  }
  EXPECT_EQ(lobes.size(), expected);
}

TEST(ReferencePndf, PeriodicImagesCoverFootprintsWiderThanTheMap) {
  // An 8x8 wrapped map and the same map tiled 4x4 are the same infinite surface.
  const bake::NormalMap small = testing::wavyMap(8, 8);
  const FlakeSet a = buildFlakes(small);
  const FlakeSet b = buildFlakes(testing::tile(small, 4, 4));
  const Footprint fp = {3.3, 30.1, 9.0};  // 6 sigma = 54 texels: many images of every flake
  EXPECT_EQ(footprintLobes(a, fp, 0.005).size(), footprintLobes(b, fp, 0.005).size());
  for (double sx : {-0.2, 0.0, 0.13}) {
    const double va = evalPndf(a, fp, sx, 0.05, 0.02);
    const double vb = evalPndf(b, fp, sx, 0.05, 0.02);
    EXPECT_NEAR(va, vb, 1e-12 * std::max(1.0, vb));
  }
}

TEST(ReferencePndf, EdgeFootprintEqualsCentreOfRolledMap) {
  const bake::NormalMap map = testing::wavyMap(20, 14);
  const FlakeSet set = buildFlakes(map, 2);
  const FlakeSet rolled = buildFlakes(testing::roll(map, 10, 7), 2);
  const Footprint edge = {0.3, 13.6, 2.0};
  const Footprint centre = {10.3, 6.6, 2.0};
  for (double sx : {-0.3, -0.1, 0.05, 0.2}) {
    for (double sy : {-0.25, 0.0, 0.15}) {
      const double v_edge = evalPndf(set, edge, sx, sy, 0.02);
      const double v_centre = evalPndf(rolled, centre, sx, sy, 0.02);
      EXPECT_NEAR(v_edge, v_centre, 1e-12 * std::max(1.0, v_centre));
    }
  }
}

}  // namespace
}  // namespace glintbake::reference
