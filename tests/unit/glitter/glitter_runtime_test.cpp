// SPDX-License-Identifier: Apache-2.0
// The glitter asset through the runtime (GlitterNdf, openNdfAsset): record checks, pdf / eval /
// mass consistency, a chi-square test of its sampler, and glitter pyramids baked by the pyramid
// builder passing the tests normal-map pyramids pass (integral 1, chi-square of the sampler).
#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/container.h>
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/glitter_ndf.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>
#include "../temp_dir.h"
#include "stats/chi_square.h"

namespace glintbake {
namespace {

bake::glitter::GlitterParams assetParams(uint64_t n, double alpha, double gamma = 0.06) {
  bake::glitter::GlitterParams p;
  p.particles = n;
  p.alpha = alpha;
  p.seed = 3;
  p.map_width = p.map_height = 256;
  p.ndf_res = 16;
  p.gamma = gamma;
  return p;
}

std::vector<uint8_t> glitterAsset(const bake::glitter::GlitterParams& p, const std::string& name) {
  const std::string file = testing::processTempDir() + name;
  bake::glitter::GlitterModel model(p);
  format::Writer w;
  EXPECT_EQ(w.open(file, format::AssetKind::kGlitter, 3), format::ContainerStatus::kOk);
  EXPECT_TRUE(bool(bake::glitter::writeGlitterSections(w, model, bake::glitter::defaultGlitterShape(p, 4.0))));
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  std::ifstream f(file, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

struct S {
  double sx, sy;
};

// n samples of a source's NDF for one footprint.
std::vector<S> drawSamples(const runtime::NdfSource& src, const runtime::Footprint& f, int n, uint64_t seed) {
  std::vector<S> samples;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    runtime::NdfSample smp;
    EXPECT_EQ(src.sample(f, u(rng), u(rng), &smp), runtime::RuntimeStatus::kOk);
    samples.push_back({smp.s.x, smp.s.y});
  }
  return samples;
}

runtime::Footprint fp(double x, double y, double sigma) {
  runtime::Footprint f;
  f.x = x, f.y = y, f.sigma = sigma;
  return f;
}

TEST(GlitterRuntime, OpensThroughOpenNdfAssetAndRefusesBadRecords) {
  const auto bytes = glitterAsset(assetParams(1000000, 0.3), "glitter_open.gbk");
  std::unique_ptr<runtime::NdfSource> src;
  ASSERT_EQ(runtime::openNdfAssetMemory(bytes.data(), bytes.size(), &src), runtime::RuntimeStatus::kOk);
  EXPECT_EQ(src->kind(), format::AssetKind::kGlitter);
  EXPECT_EQ(src->resolution(), 16);
  EXPECT_EQ(src->mapSize().width, 256);
  runtime::GlitterNdf g;
  ASSERT_EQ(g.openMemory(bytes.data(), bytes.size()), runtime::RuntimeStatus::kOk);
  format::GlitterRecord rec = g.record();
  EXPECT_EQ(format::checkGlitterRecord(rec), nullptr);
  for (int field = 0; field < 4; ++field) {
    format::GlitterRecord r = rec;
    if (field == 0) r.particles = 0;
    if (field == 1) r.alpha = 0.0;
    if (field == 2) r.gamma = -1.0;
    if (field == 3) r.map_width = 0;
    EXPECT_NE(format::checkGlitterRecord(r), nullptr) << field;
  }
  // A flipped byte anywhere in the record or table is caught (by a checksum or a record check).
  std::vector<uint8_t> bad = bytes;
  bad[130] ^= 0x40;
  EXPECT_NE(runtime::openNdfAssetMemory(bad.data(), bad.size(), &src), runtime::RuntimeStatus::kOk);
}

TEST(GlitterRuntime, PdfIsEvalOverMassAndSamplesCarryTheirPdf) {
  const auto bytes = glitterAsset(assetParams(200000, 0.3), "glitter_pdf.gbk");
  runtime::GlitterNdf g;
  ASSERT_EQ(g.openMemory(bytes.data(), bytes.size()), runtime::RuntimeStatus::kOk);
  const runtime::Footprint f = fp(40.0, 200.0, 3.0);
  double m = 0.0;
  ASSERT_EQ(g.mass(f, &m), runtime::RuntimeStatus::kOk);
  EXPECT_NEAR(m, 1.0, 0.15);  // about 1400 facets under the footprint
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    runtime::NdfSample smp;
    ASSERT_EQ(g.sample(f, u(rng), u(rng), &smp), runtime::RuntimeStatus::kOk);
    double p = 0.0, e = 0.0;
    ASSERT_EQ(g.pdf(f, smp.s, &p), runtime::RuntimeStatus::kOk);
    ASSERT_EQ(g.eval(f, smp.s, &e), runtime::RuntimeStatus::kOk);
    EXPECT_GT(p, 0.0);
    EXPECT_EQ(smp.pdf, p);
    EXPECT_NEAR(p, e / m, 1e-12 * p);
  }
  // Same query, same answer; argument checks.
  double a = 0.0, b = 0.0;
  g.eval(f, {0.1, 0.2}, &a);
  g.eval(f, {0.1, 0.2}, &b);
  EXPECT_EQ(a, b);
  EXPECT_EQ(g.eval(fp(1, 1, -1), {0, 0}, &a), runtime::RuntimeStatus::kInvalidArgument);
  runtime::NdfSample smp;
  EXPECT_EQ(g.sample(f, 1.0, 0.5, &smp), runtime::RuntimeStatus::kInvalidArgument);
}

// The sampler against the density it reports: samples binned on a coarse grid, expected counts
// from eval / mass integrated over each bin by a midpoint rule.
TEST(GlitterRuntime, SamplerPassesChiSquare) {
  // Wide cones (0.2 rad) keep the midpoint rule of the expected counts accurate.
  const auto bytes = glitterAsset(assetParams(60000, 0.25, 0.2), "glitter_chi2.gbk");
  runtime::GlitterNdf g;
  ASSERT_EQ(g.openMemory(bytes.data(), bytes.size()), runtime::RuntimeStatus::kOk);
  const runtime::Footprint f = fp(100.0, 60.0, 1.5);  // about 50 facets under the footprint
  const int res = 8, sub = 12;
  double m = 0.0;
  g.mass(f, &m);
  std::vector<double> image(size_t(res) * res, 0.0);
  const double h = 2.0 / res;
  for (int j = 0; j < res; ++j) {
    for (int i = 0; i < res; ++i) {
      double sum = 0.0;
      for (int b = 0; b < sub; ++b) {
        for (int a = 0; a < sub; ++a) {
          double e = 0.0;
          g.eval(f, {-1 + (i + (a + 0.5) / sub) * h, 1 - (j + (b + 0.5) / sub) * h}, &e);
          sum += e;
        }
      }
      image[size_t(j) * res + i] = sum / (sub * sub);
    }
  }
  const std::vector<S> samples = drawSamples(g, f, 5000, 17);
  const stats::ChiSquareResult r = stats::chiSquareNdfTest(samples, image, res, m);
  std::printf("[ measured ] glitter sampler chi-square p = %.4f (%d dof)\n", r.p_value, r.dof);
  EXPECT_GT(r.p_value, 0.01);
}

TEST(GlitterPyramid, BakedPyramidIntegratesToOneAndSamples) {
  bake::glitter::GlitterParams p = assetParams(20000, 0.3);
  p.map_width = p.map_height = 64;
  bake::glitter::GlitterModel model(p);
  bake::ndf::PyramidOptions opt;
  opt.splat.ndf_res = 32;
  opt.stride0 = 16;
  opt.sigma0 = 4;
  opt.levels = 3;
  bake::glitter::GlitterImageSource source(model, opt.splat.ndf_res, opt.sigma0);
  const std::string file = testing::processTempDir() + "glitter_pyramid.gbk";
  format::Writer w;
  ASSERT_EQ(w.open(file, format::AssetKind::kNdfPyramid, 3), format::ContainerStatus::kOk);
  bake::ndf::PyramidReport rep;
  ASSERT_TRUE(bool(bake::ndf::buildNdfPyramid(source, opt, w, &rep)));
  ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
  runtime::NdfPyramid pyr;
  ASSERT_EQ(pyr.open(file.c_str()), runtime::RuntimeStatus::kOk);
  for (const runtime::Footprint& f : {fp(8, 8, 4), fp(25, 37, 6), fp(60, 60, 16)}) {
    double m = 0.0;
    ASSERT_EQ(pyr.mass(f, &m), runtime::RuntimeStatus::kOk);
    // A footprint holds a random number of facets: its mass is 1 within the Poisson noise of the
    // effective count N 4 pi sigma^2 / map area ...
    const double effective = double(p.particles) * 4.0 * kPi * f.sigma * f.sigma / (64.0 * 64.0);
    EXPECT_NEAR(m, 1.0, 5.0 / std::sqrt(effective)) << f.x;
    // ... and at a stored centre it is exactly the surface's weighted facets (up to the facets
    // binned outside the unit disk and float rounding).
    if (f.x == 8.0) {
      format::GlitterGaussian g;
      g.u = g.v = 8.0 / 64.0;
      g.sigma_u = g.sigma_v = 4.0 / 64.0;
      const double direct =
          format::glitterWeightedCount(model.view(), source.shape(), g, format::GlitterDirRegion::all(), nullptr) /
          double(p.particles);
      EXPECT_NEAR(m, direct, 2e-3 * direct);
    }
    std::vector<float> img(32 * 32);
    ASSERT_EQ(pyr.image(f, img.data(), img.size()), runtime::RuntimeStatus::kOk);
    std::vector<double> image(img.begin(), img.end());
    const std::vector<S> samples = drawSamples(pyr, f, 100000, 23);
    const stats::ChiSquareResult r = stats::chiSquareNdfTest(samples, image, 32, m);
    std::printf("[ measured ] glitter pyramid sigma %.0f: mass %.5f, chi-square p = %.4f\n", f.sigma, m, r.p_value);
    EXPECT_GT(r.p_value, 0.01);
  }
}

}  // namespace
}  // namespace glintbake
