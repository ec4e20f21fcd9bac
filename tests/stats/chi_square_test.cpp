// SPDX-License-Identifier: Apache-2.0
// The chi-square helper itself: the incomplete gamma function against tabulated chi-square
// quantiles, pooling of small cells, and the verdicts on known-good and known-bad histograms.
#include "chi_square.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace glintbake::stats {
namespace {

TEST(ChiSquare, SurvivalMatchesTabulatedQuantiles) {
  // Upper quantiles of the chi-square distribution (the 5% and 1% points, to 16 digits).
  struct Row {
    int dof;
    double x, p;
  };
  const Row rows[] = {{1, 3.841458820694124, 0.05},  {1, 6.634896601021214, 0.01},
                      {2, 5.991464547107979, 0.05},  {5, 11.070497693516351, 0.05},
                      {10, 23.209251158954356, 0.01}, {30, 43.77297182574219, 0.05},
                      {100, 124.34211340400407, 0.05}, {1000, 1106.9689943522174, 0.01}};
  for (const Row& r : rows) {
    EXPECT_NEAR(chiSquareSurvival(r.x, r.dof), r.p, r.p * 1e-7) << "dof " << r.dof;
  }
  // Closed forms: dof 2 is an exponential, Q(1, x) = e^-x; dof 1 is 1 - erf(sqrt(x / 2)).
  for (double x : {0.01, 0.5, 1.9, 2.1, 7.0, 40.0}) {
    EXPECT_NEAR(chiSquareSurvival(x, 2), std::exp(-0.5 * x), 1e-14);
    EXPECT_NEAR(chiSquareSurvival(x, 1), std::erfc(std::sqrt(0.5 * x)), 1e-13);
  }
  EXPECT_EQ(chiSquareSurvival(0.0, 7), 1.0);
  EXPECT_LT(chiSquareSurvival(500.0, 10), 1e-90);
}

TEST(ChiSquare, PerfectFitPassesAndBadFitFails) {
  const std::vector<double> expected = {100, 200, 300, 400};
  EXPECT_NEAR(chiSquareTest(expected, expected).p_value, 1.0, 1e-12);
  const std::vector<double> skewed = {150, 200, 300, 350};
  const ChiSquareResult bad = chiSquareTest(skewed, expected);
  EXPECT_NEAR(bad.statistic, 2500.0 / 100 + 2500.0 / 400, 1e-12);
  EXPECT_EQ(bad.dof, 3);
  EXPECT_LT(bad.p_value, 1e-5);
}

TEST(ChiSquare, PoolsCellsWithSmallExpectations) {
  // Three cells below 5 pool into one of expected 6; the others stay.
  const std::vector<double> expected = {2, 2, 2, 50, 44};
  const std::vector<double> observed = {0, 1, 5, 50, 44};
  const ChiSquareResult r = chiSquareTest(observed, expected);
  EXPECT_EQ(r.pooled, 3);
  EXPECT_EQ(r.cells, 3);
  EXPECT_NEAR(r.statistic, 0.0, 1e-12);
  // A pooled cell still below 5 joins the smallest regular cell.
  const ChiSquareResult merged = chiSquareTest({1, 48, 51}, {1, 49, 50});
  EXPECT_EQ(merged.cells, 2);
  EXPECT_NEAR(merged.statistic, 1.0 / 50 + 1.0 / 50, 1e-12);
}

TEST(ChiSquare, SampleWhereNoneExpectedFails) {
  const ChiSquareResult r = chiSquareTest({1, 50, 49}, {0, 50, 50});
  EXPECT_EQ(r.p_value, 0.0);
  EXPECT_FALSE(r.passed(0.01));
}

TEST(ChiSquare, NdfBinLayoutFollowsTheSpec) {
  // Row 0 is the top (s_y = +1), column 0 the left (s_x = -1).
  EXPECT_EQ(ndfBinIndex(-0.99, 0.99, 4), 0);
  EXPECT_EQ(ndfBinIndex(0.99, 0.99, 4), 3);
  EXPECT_EQ(ndfBinIndex(-0.99, -0.99, 4), 12);
  EXPECT_EQ(ndfBinIndex(0.1, 0.1, 4), 1 * 4 + 2);
  EXPECT_EQ(ndfBinIndex(1.2, 0.0, 4), -1);
  EXPECT_EQ(ndfBinIndex(0.0, -1.0001, 4), -1);
}

}  // namespace
}  // namespace glintbake::stats
