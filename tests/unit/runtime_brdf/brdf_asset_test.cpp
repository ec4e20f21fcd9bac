// SPDX-License-Identifier: Apache-2.0
// The microfacet BRDF on a baked P-NDF (ndf-pyramid assets through NdfSource): the s-plane to
// solid-angle conversion against the flat map's analytic lobe, a white furnace of a flat-map
// asset, reciprocity, and sampling (chi-square, sample pdf == pdf()).
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/brdf.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/sg.h>

#include <gtest/gtest.h>

#include "test_util.h"

#include <cmath>
#include <memory>
#include <string>
#include "../temp_dir.h"

namespace glintbake::runtime {
namespace {

using testing::chiSquare;
using testing::Rng;
using testing::sphericalDirection;

std::unique_ptr<NdfSource> bakePyramid(bake::MapKind kind, double alpha, int ndf_res, double sigma_r,
                                       const std::string& name) {
  bake::MapParams mp;
  mp.size = 32;
  mp.seed = 4;
  mp.alpha = alpha;
  const bake::NormalMap map = bake::generateMap(kind, mp);
  bake::ndf::PyramidOptions o;
  o.splat.ndf_res = ndf_res;
  o.splat.sigma_r = sigma_r;
  o.stride0 = 8;
  o.sigma0 = 4;
  o.levels = 2;
  const std::string path = glintbake::testing::processTempDir() + "" + name + ".gbk";
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kNdfPyramid, 3), format::ContainerStatus::kOk);
  EXPECT_TRUE(bake::ndf::buildNdfPyramid(map, o, w, nullptr).ok());
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  std::unique_ptr<NdfSource> source;
  EXPECT_EQ(openNdfAsset(path.c_str(), &source), RuntimeStatus::kOk);
  return source;
}

// A flat map's P-NDF is N(s; 0, sigma_r^2 I) per unit s-plane area; as a microfacet D it is the
// Beckmann lobe of alpha = sqrt(2) sigma_r near the normal (tan(theta) ~ |s|), and multiplied by
// cos(theta_h) it integrates to 1 over solid angle.
TEST(BrdfAsset, FlatMapNdfIsABeckmannLobeInSolidAngle) {
  bake::MapParams mp;
  mp.size = 16;
  const reference::FlakeSet flakes = reference::buildFlakes(bake::generateMap(bake::MapKind::kFlat, mp), 1);
  const double sigma_r = 0.02;
  reference::Footprint fp;
  fp.x = 8.0;
  fp.y = 8.0;
  fp.sigma = 3.0;
  const double alpha = std::sqrt(2.0) * sigma_r;
  for (double r : {0.0, 0.01, 0.02, 0.04}) {
    const double d_s = reference::evalPndf(flakes, fp, r, 0.0, sigma_r);
    const Vec3 h = normalize(Vec3{r, 0.0, std::sqrt(1.0 - r * r)});
    EXPECT_NEAR(d_s, microfacetD(MicrofacetModel::kBeckmann, alpha, h), 5e-3 * d_s) << r;
  }
  // integral over the hemisphere of D_s(h_x, h_y) cos(theta_h) dw_h (quadrature in theta, phi).
  const int nt = 2000;
  double integral = 0.0;
  const double theta_max = 0.2;  // 7 sigma
  for (int i = 0; i < nt; ++i) {
    const double theta = (i + 0.5) * theta_max / nt;
    const double d_s = reference::evalPndf(flakes, fp, std::sin(theta), 0.0, sigma_r);
    integral += d_s * std::cos(theta) * std::sin(theta) * (theta_max / nt) * 2.0 * kPi;
  }
  EXPECT_NEAR(integral, 1.0, 2e-3);
}

// White furnace: a flat-map asset under a uniform white environment with F = 1 and a tiny
// shadowing roughness reflects everything: the albedo (mean of the sample weights) is 1 to the
// asset's mass accuracy, whatever the view direction.
TEST(BrdfAsset, WhiteFurnaceOfFlatMapAsset) {
  const auto source = bakePyramid(bake::MapKind::kFlat, 0.3, 64, 0.005, "brdf_flat");
  ASSERT_TRUE(source);
  Footprint fp;
  fp.x = 13.0;
  fp.y = 7.5;
  fp.sigma = 5.0;
  double mass = 0.0;
  ASSERT_EQ(source->mass(fp, &mass), RuntimeStatus::kOk);
  EXPECT_NEAR(mass, 1.0, 1e-3);
  const MicrofacetBrdf brdf = MicrofacetBrdf::glinty(source.get(), fp, MicrofacetModel::kGgx, 1e-3, Fresnel{});
  for (double theta_o : {0.0, 0.5, 1.0}) {
    const Vec3 wo{std::sin(theta_o), 0.0, std::cos(theta_o)};
    const int n = 128;
    double albedo = 0.0;
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        BrdfSample s;
        ASSERT_EQ(brdf.sample(wo, (a + 0.5) / n, (b + 0.5) / n, &s), RuntimeStatus::kOk);
        albedo += s.weight.r;
      }
    }
    EXPECT_NEAR(albedo / (double(n) * n), 1.0, 1e-2) << "theta_o " << theta_o;
  }
}

TEST(BrdfAsset, ReciprocityAndSamplingOfARoughMapAsset) {
  const auto source = bakePyramid(bake::MapKind::kBeckmann, 0.5, 32, 0.02, "brdf_rough");
  ASSERT_TRUE(source);
  Footprint fp;
  fp.x = 16.0;
  fp.y = 16.0;
  fp.sigma = 8.0;
  Fresnel gold;
  gold.kind = FresnelKind::kConductor;
  const MicrofacetBrdf brdf = MicrofacetBrdf::glinty(source.get(), fp, MicrofacetModel::kBeckmann, 0.5, gold);
  Rng rng(21);
  for (int i = 0; i < 500; ++i) {
    const Vec3 wi = sphericalDirection(rng.next(), 2.0 * kPi * rng.next());
    const Vec3 wo = sphericalDirection(rng.next(), 2.0 * kPi * rng.next());
    Rgb a, b;
    ASSERT_EQ(brdf.eval(wi, wo, &a), RuntimeStatus::kOk);
    ASSERT_EQ(brdf.eval(wo, wi, &b), RuntimeStatus::kOk);
    EXPECT_NEAR(a.g, b.g, 1e-12 * std::fmax(1.0, a.g));
  }
  const Vec3 wo = normalize(Vec3{0.3, -0.2, 0.9});
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
  const testing::ChiSquareResult r = chiSquare(sample, pdf, 300000, 5, 24, 48, 12);
  EXPECT_LT(r.statistic, r.threshold) << "dof " << r.dof;
  EXPECT_NEAR(r.sampled_mass, r.integrated_mass, 1e-2);

  // The prefiltered SG shading averages this NDF: for a sharp light it matches Monte Carlo with
  // the asset's D (light sampling) within the piecewise-constant resolution of the NDF.
  SphericalGaussian sg;
  sg.axis = normalize(Vec3{-0.2, 0.25, 0.95});
  sg.sharpness = 400.0;
  Rgb pre;
  ASSERT_EQ(prefilteredSgShading(brdf, sg, 1e-4, wo, &pre), RuntimeStatus::kOk);
  double mc = 0.0;
  const int n = 50000;
  for (int i = 0; i < n; ++i) {
    double p = 0.0;
    const Vec3 wi = sampleSg(sg, rng.next(), rng.next(), &p);
    Rgb f;
    ASSERT_EQ(brdf.eval(wi, wo, &f), RuntimeStatus::kOk);
    mc += f.r * evalSg(sg, wi).r * std::fmax(0.0, wi.z) / p;
  }
  mc /= n;
  // The prefilter averages the NDF over a square of the support's size: its error depends on the
  // NDF's structure inside that square (15% for the trilinear blend of this asset, 23% for the
  // Gaussian footprint blend, whose NDF at this footprint carries more of the map's structure).
  EXPECT_NEAR(pre.r, mc, 0.25 * mc);
}

}  // namespace
}  // namespace glintbake::runtime
