// SPDX-License-Identifier: Apache-2.0
// Spherical Gaussian lights: integral, support cone, half-vector rectangle, sampling and the
// prefiltered shading against a Monte Carlo reference.
#include <glintbake/runtime/sg.h>

#include <gtest/gtest.h>

#include "test_util.h"

#include <cmath>

namespace glintbake::runtime {
namespace {

using testing::Rng;
using testing::sphericalDirection;

SphericalGaussian makeSg(const Vec3& axis, double lambda, double a) {
  SphericalGaussian sg;
  sg.axis = normalize(axis);
  sg.sharpness = lambda;
  sg.amplitude = Rgb{a, 0.5 * a, 2.0 * a};
  return sg;
}

// Quadrature over the sphere in (z, phi), fine enough for lambda up to a few hundred when the axis
// is tilted.
double integrateOverSphere(const SphericalGaussian& sg) {
  const int nz = 4000, nphi = 1000;
  double sum = 0.0;
  for (int i = 0; i < nz; ++i) {
    const double z = -1.0 + (i + 0.5) * 2.0 / nz;
    for (int j = 0; j < nphi; ++j) sum += evalSg(sg, sphericalDirection(z, (j + 0.5) * 2.0 * kPi / nphi)).r;
  }
  return sum * (2.0 / nz) * (2.0 * kPi / nphi);
}

TEST(Sg, IntegralMatchesQuadrature) {
  for (double lambda : {0.01, 1.0, 10.0, 150.0}) {
    const SphericalGaussian sg = makeSg(Vec3{0.3, -0.5, 0.8}, lambda, 1.7);
    const double expected = 2.0 * kPi * 1.7 * (1.0 - std::exp(-2.0 * lambda)) / lambda;
    EXPECT_NEAR(sgIntegral(sg).r, expected, 1e-12 * expected);
    EXPECT_NEAR(sgIntegral(sg).b, 2.0 * expected, 2e-12 * expected);
    EXPECT_NEAR(integrateOverSphere(sg), expected, 2e-3 * expected) << lambda;
  }
}

TEST(Sg, SupportConeBoundaryEqualsEpsilon) {
  const SphericalGaussian sg = makeSg(Vec3{0, 0, 1}, 50.0, 2.0);  // largest channel: 4
  const double eps = 0.01;
  const SgSupport support = sgSupport(sg, eps);
  ASSERT_FALSE(support.empty);
  EXPECT_NEAR(support.cos_theta_max, 1.0 + std::log(eps / 4.0) / 50.0, 1e-15);
  const double c = support.cos_theta_max;
  const Vec3 edge{std::sqrt(1.0 - c * c), 0.0, c};
  EXPECT_NEAR(evalSg(sg, edge).b, eps, 1e-12);
  const Vec3 inside = normalize(Vec3{0.5 * edge.x, 0.0, edge.z});
  EXPECT_GT(evalSg(sg, inside).b, eps);
  // Broad lobes and tiny eps: the whole sphere; eps above the amplitude: nothing.
  EXPECT_EQ(sgSupport(makeSg(Vec3{0, 0, 1}, 0.5, 1.0), 1e-3).cos_theta_max, -1.0);
  EXPECT_TRUE(sgSupport(sg, 5.0).empty);
}

// Every half vector of a direction in the support cone lies in the rectangle, and the rectangle
// is not much larger than the region those half vectors cover.
TEST(Sg, HalfVectorRectangleBoundsTheSupport) {
  Rng rng(3);
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 axis = sphericalDirection(0.2 + 0.8 * rng.next(), 2.0 * kPi * rng.next());
    const Vec3 wo = sphericalDirection(0.1 + 0.9 * rng.next(), 2.0 * kPi * rng.next());
    const double lambda = trial < 20 ? 300.0 : 20.0;
    const SphericalGaussian sg = makeSg(axis, lambda, 1.0);
    const double eps = 1e-3;
    SRect rect;
    bool has = false;
    ASSERT_EQ(sgHalfVectorRect(sg, eps, wo, &rect, &has), RuntimeStatus::kOk);
    ASSERT_TRUE(has);
    const double c = sgSupport(sg, eps).cos_theta_max;
    double x0 = 2, x1 = -2, y0 = 2, y1 = -2;
    for (int n = 0; n < 4000; ++n) {
      // Uniform in the cap: z uniform in [c, 1] around the axis.
      const double z = c + (1.0 - c) * rng.next();
      const Vec3 local = sphericalDirection(z, 2.0 * kPi * rng.next());
      Vec3 t = normalize(std::fabs(axis.x) > 0.5 ? cross(axis, Vec3{0, 1, 0}) : cross(axis, Vec3{1, 0, 0}));
      const Vec3 b = cross(axis, t);
      const Vec3 wi = local.x * t + local.y * b + local.z * axis;
      if (dot(wi + wo, wi + wo) < 1e-12) continue;
      const Vec3 h = normalize(wi + wo);
      EXPECT_GE(h.x, rect.x0 - 1e-12);
      EXPECT_LE(h.x, rect.x1 + 1e-12);
      EXPECT_GE(h.y, rect.y0 - 1e-12);
      EXPECT_LE(h.y, rect.y1 + 1e-12);
      x0 = std::fmin(x0, h.x);
      x1 = std::fmax(x1, h.x);
      y0 = std::fmin(y0, h.y);
      y1 = std::fmax(y1, h.y);
    }
    const double sampled_area = (x1 - x0) * (y1 - y0);
    const double rect_area = (rect.x1 - rect.x0) * (rect.y1 - rect.y0);
    // Tightness matters for sharp lobes (the glint regime); broad cones only need containment.
    if (lambda >= 300.0) {
      EXPECT_LT(rect_area, 1.6 * sampled_area + 1e-6) << "trial " << trial;
    }
  }
}

TEST(Sg, SamplingDensityIsConsistent) {
  const SphericalGaussian sg = makeSg(Vec3{0.2, 0.1, 1.0}, 30.0, 1.0);
  const Rgb integral = sgIntegral(sg);
  Rng rng(5);
  double mean_cos = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    double pdf = 0.0;
    const Vec3 v = sampleSg(sg, rng.next(), rng.next(), &pdf);
    EXPECT_NEAR(std::sqrt(dot(v, v)), 1.0, 1e-12);
    // The sampling density is G / integral(G).
    if (i < 1000) {
      EXPECT_NEAR(pdf, evalSg(sg, v).r / integral.r, 1e-9 * pdf);
    }
    mean_cos += dot(v, sg.axis);
  }
  // E[cos] = coth(lambda) - 1 / lambda for the (normalised) SG.
  const double lambda = sg.sharpness;
  EXPECT_NEAR(mean_cos / n, 1.0 / std::tanh(lambda) - 1.0 / lambda, 1e-3);
}

// For a sharp light the prefiltered shading of a smooth BRDF agrees with a Monte Carlo estimate of
// the integral of f G cos(theta_i) (light sampling).
TEST(Sg, PrefilteredShadingMatchesMonteCarloForSharpLights) {
  Fresnel schlick;
  schlick.kind = FresnelKind::kSchlick;
  schlick.f0 = Rgb{0.9, 0.6, 0.3};
  const MicrofacetBrdf brdf = MicrofacetBrdf::smooth(MicrofacetModel::kBeckmann, 0.3, schlick);
  const SphericalGaussian sg = makeSg(Vec3{0.3, 0.2, 0.9}, 800.0, 1.0);
  const Vec3 wo = normalize(Vec3{-0.4, 0.1, 0.9});
  Rgb pre;
  ASSERT_EQ(prefilteredSgShading(brdf, sg, 1e-4, wo, &pre), RuntimeStatus::kOk);
  Rng rng(9);
  double mc = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    double pdf = 0.0;
    const Vec3 wi = sampleSg(sg, rng.next(), rng.next(), &pdf);
    Rgb f;
    ASSERT_EQ(brdf.eval(wi, wo, &f), RuntimeStatus::kOk);
    mc += f.r * evalSg(sg, wi).r * std::fmax(0.0, wi.z) / pdf;
  }
  mc /= n;
  EXPECT_GT(mc, 0.0);
  EXPECT_NEAR(pre.r, mc, 0.05 * mc);
  // Light below the horizon: nothing.
  Rgb none;
  ASSERT_EQ(prefilteredSgShading(brdf, makeSg(Vec3{0, 0.2, -1}, 800.0, 1.0), 1e-4, wo, &none), RuntimeStatus::kOk);
  EXPECT_EQ(none.g, 0.0);
  // Invalid input.
  EXPECT_EQ(prefilteredSgShading(brdf, sg, 0.0, wo, &none), RuntimeStatus::kInvalidArgument);
}

}  // namespace
}  // namespace glintbake::runtime
