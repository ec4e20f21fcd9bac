// SPDX-License-Identifier: Apache-2.0
// Multi-scale roughness relations (Tao et al. 2021): eq. 4 against quadrature, the limits and the
// clamp of alpha_me(|b|), and the refits against the paper's formula on the same ground truth.
#include <glintbake/bake/ltc/multiscale.h>
#include <glintbake/format/numbers.h>

#include <gtest/gtest.h>

#include <cmath>

namespace glintbake::bake::ltc {
namespace {

// Independent quadrature of eq. 4 in the polar angle: 2 * integral cos^2 sin / sqrt(a^2 sin^2 + cos^2).
double meanLengthByAngle(double alpha) {
  constexpr int kSteps = 200000;
  const double h = 0.5 * kPi / kSteps;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double theta = (i + 0.5) * h;
    const double c = std::cos(theta), s = std::sin(theta);
    sum += c * c * s / std::sqrt(alpha * alpha * s * s + c * c);
  }
  return 2.0 * sum * h;
}

TEST(Multiscale, MeanResultantLengthMatchesQuadrature) {
  for (double alpha : {0.01, 0.1, 0.3, 0.6, 0.9, 0.9995, 1.0})
    EXPECT_NEAR(meanResultantLength(alpha), meanLengthByAngle(alpha), 1e-6) << alpha;
  EXPECT_EQ(meanResultantLength(0.0), 1.0);
  EXPECT_NEAR(meanResultantLength(1.0), 2.0 / 3.0, 1e-9);
}

TEST(Multiscale, AlphaMesoLimitsAndClamp) {
  for (double alpha : {0.05, 0.2, 0.5, 0.8}) EXPECT_NEAR(alphaMesoExact(meanResultantLength(alpha)), alpha, 1e-9);
  // |b| -> 1: alpha_me -> 0, monotonically.
  double previous = 1.0;
  for (double length : {0.99, 0.999, 0.9999, 0.999999}) {
    const double exact = alphaMesoExact(length);
    const double fitted = defaultMesoFit().eval(length);
    EXPECT_LT(exact, previous);
    EXPECT_NEAR(fitted, exact, 2e-3);
    previous = exact;
  }
  EXPECT_LT(previous, 3e-3);
  EXPECT_EQ(alphaMesoExact(1.0), 0.0);
  EXPECT_EQ(defaultMesoFit().eval(1.0), 0.0);
  // The clamp at 1 below |b|(1) = 2/3.
  EXPECT_EQ(alphaMesoExact(0.6), 1.0);
  EXPECT_EQ(alphaMesoExact(0.0), 1.0);
  EXPECT_EQ(defaultMesoFit().eval(0.6), 1.0);
  EXPECT_EQ(defaultMesoFit().eval(0.2), 1.0);
}

TEST(Multiscale, ConvolutionIsExactOnTheAxesAndSymmetric) {
  EXPECT_DOUBLE_EQ(combineNumerical(0.4, 0.0), 0.4);
  EXPECT_DOUBLE_EQ(combineNumerical(0.0, 0.3), 0.3);
  // Convolving an LTC with a narrow one barely changes it; the result grows with either input.
  EXPECT_NEAR(combineNumerical(0.5, 0.01), 0.5, 0.01);
  EXPECT_NEAR(combineNumerical(0.3, 0.6), combineNumerical(0.6, 0.3), 2e-3);
  EXPECT_GT(combineNumerical(0.3, 0.4), combineNumerical(0.3, 0.3));
  EXPECT_GT(combineNumerical(0.4, 0.3), combineNumerical(0.3, 0.3));
}

TEST(Multiscale, RefitBeatsThePaperOnTheSameGroundTruth) {
  const MultiscaleFit fit = fitMultiscale(64, 5).value();
  EXPECT_LE(fit.combine_error.rms, fit.combine_paper_error.rms);
  EXPECT_LE(fit.combine_error.max, fit.combine_paper_error.max);
  EXPECT_LT(fit.meso_error.max, 2e-3);
  // The shipped coefficients agree with a fresh refit.
  const CombineFit shipped = defaultCombineFit();
  for (double a_mi : {0.1, 0.5, 0.9})
    for (double a_me : {0.1, 0.5, 0.9}) EXPECT_NEAR(shipped.eval(a_mi, a_me), fit.combine.eval(a_mi, a_me), 0.02);
  // On the axes the refitted form is exact, the paper's is not.
  EXPECT_DOUBLE_EQ(shipped.eval(0.3, 0.0), 0.3);
  EXPECT_GT(std::abs(combinePaper(0.3, 0.0) - 0.3), 1e-3);
  EXPECT_FALSE(fitMultiscale(2, 5).ok());
}

}  // namespace
}  // namespace glintbake::bake::ltc
