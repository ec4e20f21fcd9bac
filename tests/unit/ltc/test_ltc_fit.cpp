// SPDX-License-Identifier: Apache-2.0
// LTC table fitting: the LTC integrates to the tabulated norm, the runtime's polygon integral of a
// hemisphere-sized light equals it, rectangles match a Monte Carlo integral of the BRDF, and the
// fit is deterministic for any thread count.
#include <glintbake/bake/ltc/ltc.h>
#include <glintbake/bake/ltc/table.h>
#include <glintbake/runtime/ltc.h>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <random>

namespace glintbake::bake::ltc {
namespace {

constexpr int kSize = 16;

const FittedTable& ggxTable() {
  static const FittedTable table = [] {
    TableFitOptions options;
    options.size = kSize;
    auto result = fitTable(options);
    EXPECT_TRUE(result.ok());
    return result.value();
  }();
  return table;
}

const PublishedTable& ggxPublished() {
  static const PublishedTable table = packPublished(ggxTable());
  return table;
}

// Integral over the sphere (or the upper hemisphere) of f by a midpoint rule in (cos theta, phi).
template <typename F>
double sphereIntegral(F&& f, bool upper_only, int steps = 400) {
  double sum = 0.0;
  const double z0 = upper_only ? 0.0 : -1.0;
  const double dz = (1.0 - z0) / steps, dphi = 2.0 * kPi / (2 * steps);
  for (int i = 0; i < steps; ++i) {
    const double z = z0 + (i + 0.5) * dz;
    const double r = std::sqrt(1.0 - z * z);
    for (int j = 0; j < 2 * steps; ++j) {
      const double phi = (j + 0.5) * dphi;
      sum += f(Vec3{r * std::cos(phi), r * std::sin(phi), z});
    }
  }
  return sum * dz * dphi;
}

TEST(LtcBrdf, SamplingPdfIntegratesToOne) {
  for (BrdfKind kind : {BrdfKind::kGgx, BrdfKind::kBeckmann}) {
    const Vec3 v = cellView(2, kSize);  // near normal incidence: few samples reflect below H.z = 0
    const double integral = sphereIntegral(
        [&](Vec3 l) {
          double pdf = 0.0;
          evalBrdf(kind, v, l, 0.3, &pdf);
          return pdf;
        },
        false, 600);
    EXPECT_NEAR(integral, 1.0, 5e-3) << brdfKindString(kind);
  }
}

TEST(LtcTable, NormMatchesBrdfAlbedoAndLtcIntegral) {
  const PublishedTable& table = ggxPublished();
  for (int a : {6, 10, 15}) {
    for (int t : {0, 7, 13}) {
      const Vec3 v = cellView(t, kSize);
      const double alpha = cellAlpha(a, kSize);
      const double albedo = sphereIntegral(
          [&](Vec3 l) {
            double pdf = 0.0;
            return evalBrdf(BrdfKind::kGgx, v, l, alpha, &pdf);
          },
          true);
      const Ltc ltc = ltcFromPublished(table, a, t);
      EXPECT_NEAR(ltc.magnitude, albedo, 0.02 * albedo + 1e-3) << "a=" << a << " t=" << t;
      // The LTC's own integral over the sphere is its magnitude (the tabulated norm).
      const double ltc_integral = sphereIntegral([&](Vec3 l) { return ltc.eval(l); }, false);
      EXPECT_NEAR(ltc_integral, ltc.magnitude, 0.01 * ltc.magnitude) << "a=" << a << " t=" << t;
    }
  }
}

runtime::LtcCoefficients runtimeCell(int a, int t) {
  runtime::LtcTable table;
  EXPECT_EQ(table.fromArrays(kSize, ggxPublished().ltc1.data(), ggxPublished().ltc2.data()),
            runtime::RuntimeStatus::kOk);
  const double x = double(t) / (kSize - 1);
  runtime::LtcCoefficients c;
  EXPECT_EQ(table.lookup(float(double(a) / (kSize - 1)), float(1.0 - x * x), &c), runtime::RuntimeStatus::kOk);
  return c;
}

TEST(LtcTable, HemisphereLightIntegratesToNorm) {
  // A huge quad just above the horizon covers the upper hemisphere.
  const float big = 1e5f;
  const float quad[4][3] = {{-big, -big, 1e-3f}, {big, -big, 1e-3f}, {big, big, 1e-3f}, {-big, big, 1e-3f}};
  for (int a : {8, 12, 15}) {
    for (int t : {0, 4, 8}) {
      const runtime::LtcCoefficients c = runtimeCell(a, t);
      const Ltc ltc = ltcFromPublished(ggxPublished(), a, t);
      // Exactly the LTC's mass above the horizon ...
      const double above = sphereIntegral([&](Vec3 l) { return ltc.eval(l); }, true) / ltc.magnitude;
      const float integral = runtime::ltcIntegratePolygon(c, quad, 4, false);
      EXPECT_NEAR(integral, above, 2e-3) << "a=" << a << " t=" << t;
      // ... which is the whole norm up to the part of the lobe the fit puts below the horizon.
      EXPECT_NEAR(c.norm * integral, c.norm, 0.05 * c.norm) << "a=" << a << " t=" << t;
    }
  }
}

TEST(LtcTable, RectanglesMatchMonteCarloOfBrdf) {
  struct Rect {
    float centre[3], ex[3], ey[3];  // corners centre +- ex +- ey
  };
  const Rect rects[] = {{{0.0f, 0.0f, 2.0f}, {1.0f, 0, 0}, {0, 1.0f, 0}},
                        {{1.5f, 0.3f, 1.0f}, {0.5f, 0, 0}, {0, 0.8f, 0}},
                        {{-1.0f, 0.5f, 1.5f}, {0.7f, 0, -0.2f}, {0, 0.6f, 0}},
                        {{2.0f, -1.0f, 0.8f}, {0, 0, 0.5f}, {0, 1.0f, 0}}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int a : {6, 10, 14}) {
    for (int t : {2, 7, 11}) {
      const double alpha = cellAlpha(a, kSize);
      const Vec3 v = cellView(t, kSize);
      const runtime::LtcCoefficients c = runtimeCell(a, t);
      const CellError fit_error = cellError(BrdfKind::kGgx, ltcFromPublished(ggxPublished(), a, t), v, alpha, 64);
      for (const Rect& r : rects) {
        float quad[4][3];
        for (int k = 0; k < 3; ++k) {
          quad[0][k] = r.centre[k] - r.ex[k] - r.ey[k];
          quad[1][k] = r.centre[k] + r.ex[k] - r.ey[k];
          quad[2][k] = r.centre[k] + r.ex[k] + r.ey[k];
          quad[3][k] = r.centre[k] - r.ex[k] + r.ey[k];
        }
        // Wind the quad so that it faces the shading point (normal away from the origin).
        const double nz = double(r.ex[0]) * r.ey[1] - double(r.ex[1]) * r.ey[0];
        const double nx = double(r.ex[1]) * r.ey[2] - double(r.ex[2]) * r.ey[1];
        const double ny = double(r.ex[2]) * r.ey[0] - double(r.ex[0]) * r.ey[2];
        const bool flip = nx * r.centre[0] + ny * r.centre[1] + nz * r.centre[2] < 0.0;
        if (flip) std::swap(quad[1], quad[3]);
        const double ltc_value = c.norm * runtime::ltcIntegratePolygon(c, quad, 4, false);
        // Monte Carlo of the BRDF * cos over the quad's solid angle, importance sampling the BRDF.
        constexpr int kSamples = 200000;
        double sum = 0.0;
        for (int s = 0; s < kSamples; ++s) {
          const Vec3 l = sampleBrdf(BrdfKind::kGgx, v, alpha, uniform(rng), uniform(rng));
          if (l.z <= 0.0) continue;
          // Ray from the origin along l against the quad's plane.
          const Vec3 n{nx, ny, nz};
          const Vec3 centre{r.centre[0], r.centre[1], r.centre[2]};
          const double denom = dot(n, l);
          if (std::abs(denom) < 1e-12) continue;
          const double dist = dot(n, centre) / denom;
          if (dist <= 0.0) continue;
          const Vec3 p = dist * l - centre;
          const Vec3 ex{r.ex[0], r.ex[1], r.ex[2]}, ey{r.ey[0], r.ey[1], r.ey[2]};
          if (std::abs(dot(p, ex)) > dot(ex, ex) || std::abs(dot(p, ey)) > dot(ey, ey)) continue;
          double pdf = 0.0;
          const double f = evalBrdf(BrdfKind::kGgx, v, l, alpha, &pdf);
          if (pdf > 0.0) sum += f / pdf;
        }
        const double mc_value = sum / kSamples;
        // The LTC differs from the BRDF by at most its L1 fit error (relative to the norm).
        const double tolerance = fit_error.relative_l1 * c.norm + 0.01 * c.norm;
        EXPECT_NEAR(ltc_value, mc_value, tolerance) << "a=" << a << " t=" << t << " rect centre " << r.centre[0];
      }
    }
  }
}

TEST(LtcTable, DeterministicForAnyThreadCount) {
  TableFitOptions options;
  options.size = 8;
  FittedTable one, many;
  tbb::task_arena(1).execute([&] { one = fitTable(options).value(); });
  tbb::task_arena(2).execute([&] { many = fitTable(options).value(); });
  const PublishedTable a = packPublished(one), b = packPublished(many);
  ASSERT_EQ(a.ltc1.size(), b.ltc1.size());
  EXPECT_EQ(std::memcmp(a.ltc1.data(), b.ltc1.data(), a.ltc1.size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.ltc2.data(), b.ltc2.data(), a.ltc2.size() * sizeof(float)), 0);
}

TEST(LtcTable, RefinedFitIsNoWorseThanPublished) {
  TableFitOptions options;
  options.size = 16;
  options.max_roughness_columns = 6;
  options.method = FitMethod::kPublished;
  const FittedTable published = fitTable(options).value();
  options.method = FitMethod::kRefined;
  const FittedTable refined = fitTable(options).value();
  double sum_published = 0.0, sum_refined = 0.0;
  for (size_t i = 0; i < refined.cells.size(); ++i) {
    if (!refined.cells[i].fitted) continue;
    sum_published += std::log10(published.cells[i].objective);
    sum_refined += std::log10(refined.cells[i].objective);
  }
  EXPECT_LE(sum_refined, sum_published + 1e-9);
}

TEST(LtcTable, PublishedLayoutNormalisation) {
  const PublishedTable& table = ggxPublished();
  // The isotropic roughest cell: M^-1 = diag(1/m11, 1/m11, 1) scaled by m11 -> m00 = 1, m22 = m11.
  const float* p = &table.ltc1[size_t(kSize - 1) * 4];
  EXPECT_NEAR(p[0], 1.0f, 1e-6f);
  EXPECT_NEAR(p[1], 0.0f, 1e-6f);
  EXPECT_NEAR(p[2], 0.0f, 1e-6f);
  EXPECT_GT(p[3], 0.0f);
  // Sphere table: a fully visible cap has factor 1 (z = 1), a cap below the horizon 0.
  EXPECT_NEAR(table.ltc2[size_t(kSize - 1 + kSize * (kSize / 2)) * 4 + 3], 1.0f, 1e-3f);
  EXPECT_NEAR(table.ltc2[size_t(0 + kSize * (kSize / 2)) * 4 + 3], 0.0f, 1e-6f);
  EXPECT_EQ(fitTable(TableFitOptions{BrdfKind::kGgx, 1, 32, FitMethod::kRefined, 0}).ok(), false);
}

}  // namespace
}  // namespace glintbake::bake::ltc
