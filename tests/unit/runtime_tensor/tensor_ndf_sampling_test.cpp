// SPDX-License-Identifier: Apache-2.0
// TensorNdf sampling: the density sample() reports equals pdf() bit for bit, a chi-square test of
// the samples against pdf(), and a histogram of 10^6 samples against the eval() image.
#include "../../stats/chi_square.h"
#include "cp_groups.h"
#include "tensor_assets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace glintbake::runtime::testing {
namespace {

Footprint footprintAt(double x, double y, double sigma) {
  Footprint f;
  f.x = x;
  f.y = y;
  f.sigma = sigma;
  return f;
}

struct Point {
  double sx, sy;
};

// Samples n points; checks pdf() at each against the reported density (bit for bit).
std::vector<Point> drawChecked(const TensorNdf& t, const Footprint& fp, int n, uint64_t seed) {
  Uniforms u(seed);
  std::vector<Point> pts;
  pts.reserve(size_t(n));
  int mismatches = 0;
  for (int k = 0; k < n; ++k) {
    NdfSample s;
    EXPECT_EQ(t.sample(fp, u.next(), u.next(), &s), RuntimeStatus::kOk);
    double p = -1.0;
    EXPECT_EQ(t.pdf(fp, s.s, &p), RuntimeStatus::kOk);
    if (p != s.pdf || !(p > 0.0)) ++mismatches;
    pts.push_back(Point{s.s.x, s.s.y});
  }
  EXPECT_EQ(mismatches, 0);
  return pts;
}

// Expected counts from pdf() at bin centres (pdf is constant per bin).
std::vector<double> pdfImage(const TensorNdf& t, const Footprint& fp) {
  const int res = t.resolution();
  std::vector<double> img(size_t(res) * res);
  for (int j = 0; j < res; ++j) {
    for (int i = 0; i < res; ++i) {
      double p = 0.0;
      EXPECT_EQ(t.pdf(fp, SPoint{-1.0 + (i + 0.5) * 2.0 / res, 1.0 - (j + 0.5) * 2.0 / res}, &p), RuntimeStatus::kOk);
      img[size_t(j) * res + i] = p;
    }
  }
  return img;
}

TEST(TensorNdfSampling, ChiSquareAgainstPdf) {
  for (const TensorNdf* t : {&assets().nonneg, &assets().plain, &assets().exact}) {
    for (const Footprint& fp : {footprintAt(20, 30, 6), footprintAt(61, 2, 10), footprintAt(40, 40, 40)}) {
      const std::vector<Point> pts = drawChecked(*t, fp, 100000, 41);
      // pdf() integrates to 1: the chi-square total mass is 1.
      const stats::ChiSquareResult r = stats::chiSquareNdfTest(pts, pdfImage(*t, fp), t->resolution(), 1.0);
      EXPECT_TRUE(r.passed(0.01)) << r.message;
    }
  }
}

TEST(TensorNdfSampling, ChiSquareDetectsAWrongDensity) {
  // Power check: the same samples against the pdf of another footprint must fail.
  const TensorNdf& t = assets().nonneg;
  const std::vector<Point> pts = drawChecked(t, footprintAt(20, 30, 6), 100000, 43);
  const stats::ChiSquareResult r =
      stats::chiSquareNdfTest(pts, pdfImage(t, footprintAt(52, 12, 6)), t.resolution(), 1.0);
  EXPECT_LT(r.p_value, 1e-6) << r.message;
}

TEST(TensorNdfSampling, MillionSampleHistogramMatchesEvalImage) {
  const TensorNdf& t = assets().nonneg;
  const Footprint fp = footprintAt(33, 17, 8);
  const int res = t.resolution();
  std::vector<float> img(size_t(res) * res);
  ASSERT_EQ(t.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
  double mass = 0.0;
  ASSERT_EQ(t.mass(fp, &mass), RuntimeStatus::kOk);
  const double bin_area = (2.0 / res) * (2.0 / res);
  constexpr int kSamples = 1000000;
  std::vector<double> hist(img.size(), 0.0);
  Uniforms u(99);
  for (int k = 0; k < kSamples; ++k) {
    NdfSample s;
    ASSERT_EQ(t.sample(fp, u.next(), u.next(), &s), RuntimeStatus::kOk);
    const int64_t b = stats::ndfBinIndex(s.s.x, s.s.y, res);
    ASSERT_GE(b, 0);
    hist[size_t(b)] += 1.0;
  }
  // L1 distance between the sample histogram and the normalised eval image. Sampling noise alone
  // gives about sum_b sqrt(2 p_b / (pi N)) ~ 0.01 here; a sampler off by a few percent anywhere
  // that matters would exceed the tolerance.
  double l1 = 0.0;
  for (size_t b = 0; b < img.size(); ++b) l1 += std::fabs(hist[b] / kSamples - img[b] * bin_area / mass);
  std::printf("[ figures  ] 1e6 samples vs eval image: L1 distance %.4f (tolerance 0.03)\n", l1);
  EXPECT_LT(l1, 0.03);
}

}  // namespace
}  // namespace glintbake::runtime::testing
