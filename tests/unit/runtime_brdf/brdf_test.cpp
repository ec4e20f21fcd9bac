// SPDX-License-Identifier: Apache-2.0
// The analytic parts of the microfacet BRDF: normalisation of D, the weak white furnace, energy,
// reciprocity, Fresnel limits, and sampling (chi-square and pdf agreement).
#include <glintbake/runtime/brdf.h>
#include <glintbake/runtime/glintbake_brdf_c.h>
#include <glintbake/runtime/sg.h>

#include <gtest/gtest.h>

#include "test_util.h"

#include <cmath>

namespace glintbake::runtime {
namespace {

using testing::chiSquare;
using testing::Rng;
using testing::sphericalDirection;

Vec3 dirFromAngles(double theta, double phi) {
  return Vec3{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

class ModelTest : public ::testing::TestWithParam<MicrofacetModel> {};

// integral of D(h) cos(theta_h) over the hemisphere is 1 (quadrature in cos(theta) and phi; D is
// isotropic, so one phi suffices).
TEST_P(ModelTest, DistributionIsNormalised) {
  for (double alpha : {0.05, 0.2, 0.6, 1.0}) {
    const int n = 400000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const double mu = (i + 0.5) / n;  // cos(theta_h)
      sum += microfacetD(GetParam(), alpha, Vec3{std::sqrt(1.0 - mu * mu), 0.0, mu}) * mu;
    }
    EXPECT_NEAR(sum * 2.0 * kPi / n, 1.0, 2e-3) << "alpha " << alpha;
  }
}

// Weak white furnace (Heitz 2014, section 5.3): integral over all wi of
// G1(wo) D(h) / (4 cos(theta_o)) equals 1 for every wo when Lambda matches D. In half-vector
// space (dw_i = 4 |wo.h| dw_h) this is the integral of G1(wo) D(h) max(0, wo.h) / cos(theta_o) over
// h, evaluated by quadrature in (theta_h, phi_h).
TEST_P(ModelTest, WeakWhiteFurnace) {
  for (double alpha : {0.1, 0.5, 1.0}) {
    for (double theta_o : {0.0, 0.7, 1.3}) {
      const Vec3 wo = dirFromAngles(theta_o, 0.3);
      const double g1 = 1.0 / (1.0 + smithLambda(GetParam(), alpha, wo));
      const int nt = 3000, np = 360;
      double sum = 0.0;
      for (int a = 0; a < nt; ++a) {
        const double theta = (a + 0.5) * (0.5 * kPi) / nt;
        double ring = 0.0;
        for (int b = 0; b < np; ++b) {
          const Vec3 h = dirFromAngles(theta, (b + 0.5) * 2.0 * kPi / np);
          ring += std::fmax(0.0, dot(wo, h));
        }
        sum += ring * microfacetD(GetParam(), alpha, dirFromAngles(theta, 0.0)) * std::sin(theta);
      }
      sum *= g1 / wo.z * (0.5 * kPi / nt) * (2.0 * kPi / np);
      EXPECT_NEAR(sum, 1.0, 3e-3) << "alpha " << alpha << " theta_o " << theta_o;
    }
  }
}

// Directional albedo with F = 1 never exceeds 1, is close to 1 for a smooth surface seen from
// above (height-correlated shadowing loses little there) and falls as the roughness rises
// (single scattering loses energy: Kulla and Conty 2017).
TEST_P(ModelTest, AlbedoBoundedAndNearOneWhenSmooth) {
  const Fresnel none;
  double previous = 2.0;
  for (double alpha : {0.02, 0.3, 0.8}) {
    const MicrofacetBrdf brdf = MicrofacetBrdf::smooth(GetParam(), alpha, none);
    const Vec3 wo = dirFromAngles(0.4, 1.0);
    const int n = 256;
    double albedo = 0.0;
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        BrdfSample s;
        ASSERT_EQ(brdf.sample(wo, (a + 0.5) / n, (b + 0.5) / n, &s), RuntimeStatus::kOk);
        albedo += s.weight.g;
      }
    }
    albedo /= double(n) * n;
    EXPECT_LE(albedo, 1.0 + 1e-3) << alpha;
    if (alpha <= 0.02) {
      EXPECT_GT(albedo, 0.98);
    }
    EXPECT_LT(albedo, previous);
    previous = albedo;
  }
}

TEST_P(ModelTest, EvalIsReciprocal) {
  Fresnel gold;
  gold.kind = FresnelKind::kConductor;
  const MicrofacetBrdf brdf = MicrofacetBrdf::smooth(GetParam(), 0.3, gold);
  Rng rng(7);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 wi = sphericalDirection(rng.next(), 2.0 * kPi * rng.next());
    const Vec3 wo = sphericalDirection(rng.next(), 2.0 * kPi * rng.next());
    Rgb a, b;
    ASSERT_EQ(brdf.eval(wi, wo, &a), RuntimeStatus::kOk);
    ASSERT_EQ(brdf.eval(wo, wi, &b), RuntimeStatus::kOk);
    EXPECT_NEAR(a.r, b.r, 1e-12 * std::fmax(1.0, a.r));
    EXPECT_NEAR(a.b, b.b, 1e-12 * std::fmax(1.0, a.b));
  }
}

TEST_P(ModelTest, SamplePdfMatchesPdfAndChiSquarePasses) {
  const Fresnel none;
  // Moderate roughness and view angle: the density of wi has an integrable singularity at
  // wi = -wo (wo.h -> 0) that cell quadrature cannot integrate; keep its mass negligible.
  for (double alpha : {0.15, 0.35}) {
    const MicrofacetBrdf brdf = MicrofacetBrdf::smooth(GetParam(), alpha, none);
    const Vec3 wo = dirFromAngles(0.5, 0.4);
    int checked = 0;
    auto sample = [&](double u1, double u2, Vec3* w) {
      BrdfSample s;
      EXPECT_EQ(brdf.sample(wo, u1, u2, &s), RuntimeStatus::kOk);
      if (!(s.pdf > 0.0)) return false;
      double p = 0.0;
      EXPECT_EQ(brdf.pdf(s.wi, wo, &p), RuntimeStatus::kOk);
      if (checked++ < 2000) {
        EXPECT_NEAR(p, s.pdf, 1e-9 * s.pdf);
      }
      *w = s.wi;
      return true;
    };
    auto pdf = [&](const Vec3& wi) {
      double p = 0.0;
      brdf.pdf(wi, wo, &p);
      return p;
    };
    const testing::ChiSquareResult r = chiSquare(sample, pdf, 400000, 11);
    EXPECT_LT(r.statistic, r.threshold) << "alpha " << alpha << " dof " << r.dof;
    EXPECT_NEAR(r.sampled_mass, r.integrated_mass, 5e-3);
  }
}

INSTANTIATE_TEST_SUITE_P(Models, ModelTest, ::testing::Values(MicrofacetModel::kGgx, MicrofacetModel::kBeckmann));

TEST(Fresnel, LimitsAndSchlick) {
  // A conductor's reflectance rises to 1 at grazing; at normal incidence it is
  // ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2).
  const double eta = 0.2, k = 3.9;
  EXPECT_NEAR(conductorFresnel(1.0, eta, k), ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k), 1e-12);
  EXPECT_NEAR(conductorFresnel(0.0, eta, k), 1.0, 1e-12);
  // A dielectric (k = 0, eta = 1.5) reflects 4% at normal incidence.
  EXPECT_NEAR(conductorFresnel(1.0, 1.5, 0.0), 0.04, 1e-12);
  Fresnel schlick;
  schlick.kind = FresnelKind::kSchlick;
  schlick.f0 = Rgb{0.04, 0.5, 0.9};
  EXPECT_NEAR(evalFresnel(schlick, 1.0).g, 0.5, 1e-15);
  EXPECT_NEAR(evalFresnel(schlick, 0.0).r, 1.0, 1e-15);
  EXPECT_NEAR(evalFresnel(schlick, 0.5).r, 0.04 + 0.96 * std::pow(0.5, 5), 1e-15);
}

TEST(Brdf, BelowHorizonAndInvalidInput) {
  const MicrofacetBrdf brdf = MicrofacetBrdf::smooth(MicrofacetModel::kGgx, 0.3, Fresnel{});
  Rgb f{1, 1, 1};
  ASSERT_EQ(brdf.eval(Vec3{0, 0, -1}, Vec3{0, 0, 1}, &f), RuntimeStatus::kOk);
  EXPECT_EQ(f.r, 0.0);
  EXPECT_EQ(brdf.eval(Vec3{NAN, 0, 1}, Vec3{0, 0, 1}, &f), RuntimeStatus::kInvalidArgument);
  double p = -1.0;
  ASSERT_EQ(brdf.pdf(Vec3{0, 0, 1}, Vec3{0, 0, -1}, &p), RuntimeStatus::kOk);
  EXPECT_EQ(p, 0.0);
  // A glinty BRDF without a source refuses to answer rather than crash.
  const MicrofacetBrdf broken = MicrofacetBrdf::glinty(nullptr, Footprint{}, MicrofacetModel::kGgx, 0.3, Fresnel{});
  EXPECT_EQ(broken.eval(Vec3{0, 0, 1}, Vec3{0, 0, 1}, &f), RuntimeStatus::kInvalidArgument);
}

// The C API answers exactly like the C++ classes it wraps and refuses bad parameters.
TEST(BrdfCApi, MatchesCppAndValidates) {
  gb_brdf_params p{};
  p.ndf = nullptr;
  p.model = GB_MODEL_BECKMANN;
  p.alpha = 0.25;
  p.fresnel = GB_FRESNEL_SCHLICK;
  p.f0[0] = 0.1;
  p.f0[1] = 0.2;
  p.f0[2] = 0.3;
  Fresnel fr;
  fr.kind = FresnelKind::kSchlick;
  fr.f0 = Rgb{0.1, 0.2, 0.3};
  const MicrofacetBrdf brdf = MicrofacetBrdf::smooth(MicrofacetModel::kBeckmann, 0.25, fr);
  const double wi[3] = {0.3, 0.1, std::sqrt(1.0 - 0.1)}, wo[3] = {-0.2, 0.2, std::sqrt(1.0 - 0.08)};
  double f[3], pdf_c = 0.0;
  ASSERT_EQ(gb_brdf_eval(&p, wi, wo, f), 0);
  Rgb expected;
  ASSERT_EQ(brdf.eval(Vec3{wi[0], wi[1], wi[2]}, Vec3{wo[0], wo[1], wo[2]}, &expected), RuntimeStatus::kOk);
  EXPECT_EQ(f[0], expected.r);
  EXPECT_EQ(f[2], expected.b);
  ASSERT_EQ(gb_brdf_pdf(&p, wi, wo, &pdf_c), 0);
  double pdf_cpp = 0.0;
  ASSERT_EQ(brdf.pdf(Vec3{wi[0], wi[1], wi[2]}, Vec3{wo[0], wo[1], wo[2]}, &pdf_cpp), RuntimeStatus::kOk);
  EXPECT_EQ(pdf_c, pdf_cpp);
  double wi_s[3], pdf_s = 0.0, weight[3];
  ASSERT_EQ(gb_brdf_sample(&p, wo, 0.3, 0.7, wi_s, &pdf_s, weight), 0);
  BrdfSample s;
  ASSERT_EQ(brdf.sample(Vec3{wo[0], wo[1], wo[2]}, 0.3, 0.7, &s), RuntimeStatus::kOk);
  EXPECT_EQ(pdf_s, s.pdf);
  EXPECT_EQ(wi_s[2], s.wi.z);

  gb_sg sg{{0.0, 0.6, 0.8}, 20.0, {1.0, 2.0, 3.0}};
  double integral[3];
  ASSERT_EQ(gb_sg_integral(&sg, integral), 0);
  EXPECT_NEAR(integral[1], 2.0 * 2.0 * kPi * (1.0 - std::exp(-40.0)) / 20.0, 1e-12);
  double cos_max = 0.0;
  int32_t empty = 1;
  ASSERT_EQ(gb_sg_support(&sg, 1e-3, &cos_max, &empty), 0);
  EXPECT_EQ(empty, 0);
  EXPECT_NEAR(cos_max, 1.0 + std::log(1e-3 / 3.0) / 20.0, 1e-15);
  double radiance[3];
  EXPECT_EQ(gb_sg_prefiltered_shading(&p, &sg, 1e-3, wo, radiance), 0);

  p.alpha = 0.0;  // out of range
  EXPECT_NE(gb_brdf_eval(&p, wi, wo, f), 0);
  gb_brdf_ndf* ndf = reinterpret_cast<gb_brdf_ndf*>(1);
  EXPECT_NE(gb_brdf_ndf_open("/nonexistent/asset.gbk", &ndf), 0);
  EXPECT_EQ(ndf, nullptr);
  gb_brdf_ndf_close(nullptr);
}

}  // namespace
}  // namespace glintbake::runtime
