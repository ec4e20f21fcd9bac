// SPDX-License-Identifier: Apache-2.0
// Pearson chi-square goodness-of-fit test of a sampler against its (bin-integrated) density, in the
// style of Mitsuba 3's ChiSquareTest: histogram the samples into cells, compare with the expected
// counts, pool the cells whose expected count is small, and turn the statistic into a p-value with
// the regularised upper incomplete gamma function written here (no external statistics library).
//
// A sampler passes when p is not small (the tests use p > 0.01 with a fixed seed); a deliberately
// wrong sampler must give a tiny p (below 1e-6) so that the test is known to have power.
//
// Header-only, double precision, no global state: every function is thread-safe.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace glintbake::stats {

// Regularised lower incomplete gamma P(a, x) = gamma(a, x) / Gamma(a) by its power series,
//   P(a, x) = x^a e^-x / Gamma(a + 1) * sum_n x^n / ((a + 1) ... (a + n)),
// which converges quickly for x < a + 1 (Abramowitz & Stegun 6.5.29). Requires a > 0, x >= 0.
inline double lowerGammaSeries(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < 100000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * 1e-16) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Regularised upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a) by its continued fraction
// (Abramowitz & Stegun 6.5.31), evaluated with the modified Lentz algorithm; converges quickly for
// x >= a + 1. Requires a > 0, x > 0.
inline double upperGammaContinuedFraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double f = d;
  for (int n = 1; n < 100000; ++n) {
    const double an = -n * (n - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    f *= delta;
    if (std::fabs(delta - 1.0) < 1e-16) break;
  }
  return f * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) = 1 - P(a, x) for a > 0, x >= 0: Q(a, 0) = 1, Q(a, +inf) = 0. Relative accuracy about
// 1e-14 where Q is not tiny (each branch is used where it converges and does not cancel).
inline double regularizedUpperGamma(double a, double x) {
  if (!(a > 0.0) || std::isnan(x)) return std::numeric_limits<double>::quiet_NaN();
  if (x <= 0.0) return 1.0;
  if (std::isinf(x)) return 0.0;
  if (x < a + 1.0) return 1.0 - lowerGammaSeries(a, x);
  return upperGammaContinuedFraction(a, x);
}

// Probability that a chi-square variable with `dof` degrees of freedom exceeds `statistic`.
inline double chiSquareSurvival(double statistic, int dof) {
  if (dof < 1) return std::numeric_limits<double>::quiet_NaN();
  return regularizedUpperGamma(0.5 * dof, 0.5 * statistic);
}

struct ChiSquareResult {
  double statistic = 0.0;  // Pearson's sum of (observed - expected)^2 / expected over the cells used
  int dof = 0;             // cells used - 1
  double p_value = 0.0;    // chiSquareSurvival(statistic, dof); 0 when a sample fell where nothing
                           // was expected, NaN when fewer than two cells could be formed
  int cells = 0;           // cells used, the pooled cell included
  int pooled = 0;          // input cells merged into the pooled cell (expected < min_expected)
  std::string message;     // why the test failed outright, or a short summary

  bool passed(double alpha) const { return p_value > alpha; }
};

// Pearson's test of observed counts against expected counts, cell by cell (equal sizes; the
// expected counts should sum to the number of samples, so include an "everything else" cell for
// samples outside the histogram's domain). Cells expected to hold fewer than `min_expected`
// samples are pooled into one cell (Mitsuba 3's rule); when the pooled cell still expects fewer
// than `min_expected` it is merged into the smallest regular cell. A sample in a cell whose
// expected count is 0 fails the test outright (p = 0).
inline ChiSquareResult chiSquareTest(const std::vector<double>& observed, const std::vector<double>& expected,
                                     double min_expected = 5.0) {
  ChiSquareResult result;
  if (observed.size() != expected.size()) {
    result.p_value = std::numeric_limits<double>::quiet_NaN();
    result.message = "observed and expected counts differ in length";
    return result;
  }
  std::vector<double> obs_cells, exp_cells;
  double pooled_obs = 0.0, pooled_exp = 0.0;
  for (size_t k = 0; k < observed.size(); ++k) {
    const double e = std::max(0.0, expected[k]);
    if (e == 0.0 && observed[k] > 0.0) {
      result.p_value = 0.0;
      result.statistic = std::numeric_limits<double>::infinity();
      result.message = std::to_string(observed[k]) + " sample(s) in cell " + std::to_string(k) +
                       " where none are expected";
      return result;
    }
    if (e < min_expected) {
      pooled_obs += observed[k];
      pooled_exp += e;
      ++result.pooled;
    } else {
      obs_cells.push_back(observed[k]);
      exp_cells.push_back(e);
    }
  }
  if (pooled_exp >= min_expected) {
    obs_cells.push_back(pooled_obs);
    exp_cells.push_back(pooled_exp);
  } else if (!exp_cells.empty() && result.pooled > 0) {
    const size_t smallest = size_t(std::min_element(exp_cells.begin(), exp_cells.end()) - exp_cells.begin());
    obs_cells[smallest] += pooled_obs;
    exp_cells[smallest] += pooled_exp;
  }
  result.cells = int(exp_cells.size());
  if (result.cells < 2) {
    result.p_value = std::numeric_limits<double>::quiet_NaN();
    result.message = "fewer than two cells expect " + std::to_string(min_expected) + " samples or more";
    return result;
  }
  for (size_t k = 0; k < exp_cells.size(); ++k) {
    const double diff = obs_cells[k] - exp_cells[k];
    result.statistic += diff * diff / exp_cells[k];
  }
  result.dof = result.cells - 1;
  result.p_value = chiSquareSurvival(result.statistic, result.dof);
  char text[160];
  std::snprintf(text, sizeof(text), "chi2 = %.6g, dof = %d, p = %.3g (%d cells pooled)", result.statistic,
                result.dof, result.p_value, result.pooled);
  result.message = text;
  return result;
}

// The bin of an s-plane point in the res x res NDF image layout of formats/SPEC.md (row 0 at the
// top, s_y = +1; column 0 at the left, s_x = -1), as row * res + column; -1 outside [-1, 1)^2
// (s = +1 exactly is outside, a measure-zero edge).
inline int64_t ndfBinIndex(double sx, double sy, int res) {
  const double fx = (sx + 1.0) * 0.5 * res;
  const double fy = (1.0 - sy) * 0.5 * res;
  if (!(fx >= 0.0 && fx < res && fy >= 0.0 && fy < res)) return -1;
  const int column = std::min(res - 1, int(fx));
  const int row = std::min(res - 1, int(fy));
  return int64_t(row) * res + column;
}

// Chi-square test of s-plane samples against an NDF image of bin AVERAGE densities (formats/SPEC.md
// layout) whose integral over the plane, `total_mass`, the sampler normalises away (the sample
// density is image / total_mass). Cells: the res^2 bins, plus one cell for every sample outside
// the bins that the image covers (outside [-1, 1]^2 or in a bin the image zeroes), expected
// N (1 - sum(image) bin_area / total_mass). `Sample` has members sx and sy.
template <typename Sample>
ChiSquareResult chiSquareNdfTest(const std::vector<Sample>& samples, const std::vector<double>& image, int res,
                                 double total_mass, double min_expected = 5.0) {
  const size_t bins = size_t(res) * size_t(res);
  const double n = double(samples.size());
  const double bin_area = (2.0 / res) * (2.0 / res);
  std::vector<double> observed(bins + 1, 0.0), expected(bins + 1, 0.0);
  double covered = 0.0;
  for (size_t b = 0; b < bins; ++b) {
    const double mass = image[b] * bin_area / total_mass;
    expected[b] = mass * n;
    covered += mass;
  }
  expected[bins] = std::max(0.0, 1.0 - covered) * n;
  for (const Sample& s : samples) {
    const int64_t b = ndfBinIndex(s.sx, s.sy, res);
    // A sample in a zeroed bin belongs to the "elsewhere" cell, like one outside the square.
    if (b < 0 || image[size_t(b)] == 0.0) {
      observed[bins] += 1.0;
    } else {
      observed[size_t(b)] += 1.0;
    }
  }
  return chiSquareTest(observed, expected, min_expected);
}

}  // namespace glintbake::stats
