// SPDX-License-Identifier: Apache-2.0
// The counting hierarchy of glitter surfaces (format/kinds/glitter_model.h): conservation at every
// split, agreement with explicit enumeration, additivity, determinism, the integral table, and
// convergence to the smooth NDF as N grows.
#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/format/kinds/glitter_model.h>
#include <glintbake/format/numbers.h>
#include <glintbake/reference/glitter.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace glintbake {
namespace {

using format::GlitterDirRegion;
using format::GlitterUvRegion;
using format::GlitterVec3;

bake::glitter::GlitterParams params(uint64_t n, double alpha, uint64_t seed = 7,
                                    format::GlitterDistribution d = format::GlitterDistribution::kBeckmann) {
  bake::glitter::GlitterParams p;
  p.particles = n;
  p.alpha = alpha;
  p.seed = seed;
  p.distribution = d;
  return p;
}

GlitterVec3 dirOf(double sx, double sy) { return {sx, sy, std::sqrt(1.0 - sx * sx - sy * sy)}; }

format::GlitterCountOptions exact() {
  format::GlitterCountOptions o;
  o.early_stop = false;
  return o;
}

TEST(GlitterIntegrals, TableIsValidAndSumsToOne) {
  for (auto d : {format::GlitterDistribution::kBeckmann, format::GlitterDistribution::kGgx}) {
    for (double alpha : {0.02, 0.1, 0.3, 1.0}) {
      const auto table = bake::glitter::buildGlitterIntegrals(d, alpha);
      EXPECT_EQ(format::checkGlitterIntegrals(table.data(), table.size()), nullptr) << alpha;
      const double total = table[0].integral + table[1].integral + table[2].integral + table[3].integral;
      EXPECT_NEAR(total, 1.0, 2e-4) << glitterDistributionString(d) << " alpha " << alpha;
      EXPECT_NEAR(table[0].integral, 0.25, 1e-4);  // isotropic: a quarter each
      std::printf("[ measured ] %s alpha %.2f: %zu entries, total %.7f\n", glitterDistributionString(d), alpha,
                  table.size(), total);
    }
  }
  // A corrupt table is refused.
  auto table = bake::glitter::buildGlitterIntegrals(format::GlitterDistribution::kBeckmann, 0.3);
  table[4].integral *= 2.0;  // the child at the pole
  EXPECT_NE(format::checkGlitterIntegrals(table.data(), table.size()), nullptr);
}

// The section layout rule shared by the runtime's loader and the validator: one of each.
TEST(GlitterIntegrals, LayoutIsOneRecordAndOneTable) {
  EXPECT_EQ(format::checkGlitterLayout(1, 1), nullptr);
  for (size_t infos : {0u, 2u}) EXPECT_NE(format::checkGlitterLayout(infos, 1), nullptr) << infos;
  for (size_t tables : {0u, 3u}) EXPECT_NE(format::checkGlitterLayout(1, tables), nullptr) << tables;
}

TEST(GlitterHierarchy, CountsAreConservedAtEverySplit) {
  for (uint64_t n : {uint64_t(5), uint64_t(1000), uint64_t(1000000000)}) {
    bake::glitter::GlitterModel model(params(n, 0.2));
    const format::GlitterTreeShape shape{1e-3, 1e-2};
    std::mt19937 rng(3);
    for (int path = 0; path < 50; ++path) {
      format::GlitterNode node = format::glitterRoot(model.view());
      while (node.count > 0 && !format::glitterIsLeaf(model.view(), node)) {
        format::GlitterNode c[4];
        format::glitterSplit(model.view(), shape, node, c);
        ASSERT_EQ(c[0].count + c[1].count + c[2].count + c[3].count, node.count);
        // Follow a child with facets, chosen at random.
        int j = int(rng() % 4);
        for (int k = 0; k < 4 && c[j].count == 0; ++k) j = (j + 1) % 4;
        node = c[j];
      }
    }
  }
}

TEST(GlitterHierarchy, CountsEqualExplicitEnumeration) {
  bake::glitter::GlitterModel model(params(3000, 0.3));
  const format::GlitterTreeShape shape{4e-3, 3e-2};
  const auto facets = reference::enumerateGlitterFacets(model.view(), shape);
  ASSERT_EQ(facets.size(), 3000u);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int q = 0; q < 60; ++q) {
    const GlitterUvRegion uv = GlitterUvRegion::box(u(rng), u(rng), 0.05 + 0.6 * u(rng), 0.05 + 0.6 * u(rng));
    GlitterDirRegion dir;
    switch (q % 3) {
      case 0:
        dir = GlitterDirRegion::cone(dirOf(0.6 * u(rng) - 0.3, 0.6 * u(rng) - 0.3), 0.05 + 0.3 * u(rng));
        break;
      case 1: {
        const double x = 0.8 * u(rng) - 0.6, y = 0.8 * u(rng) - 0.6;
        dir = GlitterDirRegion::rect(x, y, x + 0.3, y + 0.2);
        break;
      }
      default:
        dir = GlitterDirRegion::triangle(1 + q % 4, uint64_t(rng() % 4) << (2 * (q % 4)));
    }
    const double hier = format::glitterCount(model.view(), shape, uv, dir, exact(), nullptr);
    const uint64_t brute = reference::countGlitterFacets(facets, uv, dir);
    ASSERT_EQ(hier, double(brute)) << "query " << q;
  }
  EXPECT_EQ(format::glitterCount(model.view(), shape, GlitterUvRegion::box(0.5, 0.5, 1, 1), GlitterDirRegion::all(),
                                 exact(), nullptr),
            3000.0);
}

TEST(GlitterHierarchy, DisjointQueriesAddUp) {
  bake::glitter::GlitterModel model(params(2000000, 0.25));
  const format::GlitterTreeShape shape{1e-2, 1e-2};
  const GlitterDirRegion cone = GlitterDirRegion::cone(dirOf(0.1, -0.05), 0.1);
  // Space: a box and its two halves (the seam of the unit square inside the first one).
  const double whole =
      format::glitterCount(model.view(), shape, GlitterUvRegion::box(0.97, 0.4, 0.2, 0.1), cone, exact(), nullptr);
  const double left =
      format::glitterCount(model.view(), shape, GlitterUvRegion::box(0.92, 0.4, 0.1, 0.1), cone, exact(), nullptr);
  const double right =
      format::glitterCount(model.view(), shape, GlitterUvRegion::box(0.02, 0.4, 0.1, 0.1), cone, exact(), nullptr);
  EXPECT_GT(whole, 100.0);
  EXPECT_EQ(whole, left + right);
  // Directions: four quadrants of the s-plane add up to everything.
  const GlitterUvRegion uv = GlitterUvRegion::box(0.3, 0.6, 0.15, 0.15);
  double quadrants = 0.0;
  for (int q = 0; q < 4; ++q) {
    const double x0 = q & 1 ? 0.0 : -1.0, y0 = q & 2 ? 0.0 : -1.0;
    quadrants += format::glitterCount(model.view(), shape, uv, GlitterDirRegion::rect(x0, y0, x0 + 1.0, y0 + 1.0),
                                      exact(), nullptr);
  }
  EXPECT_EQ(quadrants, format::glitterCount(model.view(), shape, uv, GlitterDirRegion::all(), exact(), nullptr));
}

TEST(GlitterHierarchy, SameQuerySameAnswerAndNearbyQueriesAgree) {
  bake::glitter::GlitterModel model(params(100000000, 0.2));
  const GlitterUvRegion uv = GlitterUvRegion::box(0.31, 0.77, 0.01, 0.01);
  const GlitterDirRegion cone = GlitterDirRegion::cone(dirOf(0.15, 0.05), 0.02);
  const format::GlitterTreeShape shape{uv.area, 2 * kPi * (1 - std::cos(0.02))};
  const double a = format::glitterCount(model.view(), shape, uv, cone, {}, nullptr);
  const double b = format::glitterCount(model.view(), shape, uv, cone, {}, nullptr);
  EXPECT_EQ(a, b);
  // A box moved by a tenth of its side shares 90% of its area: the counts differ by about the
  // facets in the two slivers, far less than between independent realisations.
  const GlitterUvRegion moved = GlitterUvRegion::box(0.311, 0.77, 0.01, 0.01);
  const double c = format::glitterCount(model.view(), shape, moved, cone, exact(), nullptr);
  const double a_exact = format::glitterCount(model.view(), shape, uv, cone, exact(), nullptr);
  const double sliver = format::glitterCount(model.view(), shape, GlitterUvRegion::box(0.3055, 0.77, 0.001, 0.01), cone,
                                             exact(), nullptr) +
                        format::glitterCount(model.view(), shape, GlitterUvRegion::box(0.3155, 0.77, 0.001, 0.01), cone,
                                             exact(), nullptr);
  EXPECT_LE(std::fabs(c - a_exact), sliver);
  // Another seed is another surface.
  bake::glitter::GlitterModel other(params(100000000, 0.2, 8));
  EXPECT_NE(format::glitterCount(other.view(), shape, uv, cone, exact(), nullptr), a_exact);
}

TEST(GlitterHierarchy, EarlyStopStaysCloseToTheExactCount) {
  bake::glitter::GlitterModel model(params(1000000000, 0.3));
  const GlitterUvRegion uv = GlitterUvRegion::box(0.5, 0.5, 0.02, 0.02);
  const GlitterDirRegion cone = GlitterDirRegion::cone(dirOf(0.2, 0.1), 0.05);
  const format::GlitterTreeShape shape{uv.area, 2 * kPi * (1 - std::cos(0.05))};
  format::GlitterCountStats fast, slow;
  const double approx = format::glitterCount(model.view(), shape, uv, cone, {}, &fast);
  const double exact_count = format::glitterCount(model.view(), shape, uv, cone, exact(), &slow);
  std::printf("[ measured ] early stop %.1f (%llu nodes) vs exact %.0f (%llu nodes)\n", approx,
              (unsigned long long)fast.nodes, exact_count, (unsigned long long)slow.nodes);
  EXPECT_NEAR(approx, exact_count, 0.02 * exact_count);
  EXPECT_LT(fast.nodes, slow.nodes);
}

// D = count / (uvArea 2 pi (1 - cos gamma) N) estimates the mean of D cos over the cone; its
// relative L2 error over 30 directions and boxes against the smooth NDF falls like
// 1 / sqrt(expected count).
TEST(GlitterConvergence, DiscreteNdfConvergesToTheSmoothOne) {
  const double gamma = 0.05;
  const double cone_sr = 2 * kPi * (1 - std::cos(gamma));
  std::vector<double> errors;
  for (auto d : {format::GlitterDistribution::kBeckmann, format::GlitterDistribution::kGgx}) {
    errors.clear();
    for (uint64_t n : {uint64_t(10000), uint64_t(1000000), uint64_t(100000000), uint64_t(10000000000)}) {
      bake::glitter::GlitterModel model(params(n, 0.3, 11, d));
      double err2 = 0.0, norm2 = 0.0;
      for (int i = 0; i < 5; ++i) {
        for (int k = 0; k < 6; ++k) {
          const GlitterVec3 h = dirOf(-0.5 + 0.25 * i, -0.5 + 0.2 * k);
          const GlitterUvRegion uv = GlitterUvRegion::box(0.1 + 0.17 * i, 0.2 + 0.13 * k, 0.1, 0.1);
          const format::GlitterTreeShape shape{uv.area, cone_sr};
          const double c = format::glitterCount(model.view(), shape, uv, GlitterDirRegion::cone(h, gamma), {}, nullptr);
          const double dd = c / (uv.area * cone_sr * double(n));
          const double smooth = reference::smoothGlitterCone(d, 0.3, h, gamma);
          err2 += (dd - smooth) * (dd - smooth);
          norm2 += smooth * smooth;
        }
      }
      errors.push_back(std::sqrt(err2 / norm2));
      std::printf("[ measured ] %s N = %.0e: relative L2 error of D %.4f\n", glitterDistributionString(d), double(n),
                  errors.back());
    }
    for (size_t i = 1; i < errors.size(); ++i) EXPECT_LT(errors[i], errors[i - 1]);
    EXPECT_LT(errors.back(), 0.02);
  }
}

TEST(GlitterWeights, BinnedFootprintIntegratesToOne) {
  bake::glitter::GlitterModel model(params(10000000, 0.3));
  const int res = 32;
  std::vector<double> bins(size_t(res) * res, 0.0);
  format::GlitterGaussian fp;
  fp.u = 0.02, fp.v = 0.5, fp.sigma_u = fp.sigma_v = 0.03;  // across the seam
  format::glitterBinnedWeights(model.view(), {1e-2, 4e-3}, fp, res, bins.data(), nullptr);
  double sum = 0.0;
  for (double b : bins) sum += b;
  const double all =
      format::glitterWeightedCount(model.view(), {1e-2, 4e-3}, fp, GlitterDirRegion::all(), nullptr) / 1e7;
  EXPECT_NEAR(sum / 1e7, all, 2e-3);  // only facets in bins outside the unit disk are missing
  EXPECT_NEAR(all, 1.0, 0.02);        // ~ 3e4 facets in the footprint: 1% noise
}

}  // namespace
}  // namespace glintbake
