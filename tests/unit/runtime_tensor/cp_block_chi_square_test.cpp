// SPDX-License-Identifier: Apache-2.0
// Chi-square tests of the CP block sampler (the runtime's counterpart of tests/stats): binned
// sample counts against the (clamped) model values and against pdf(); a deliberately mismatched
// sampler must fail.
#include <glintbake/runtime/cp_block.h>

#include "cp_groups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace glintbake::runtime {
namespace {

using testing::makeBlend;
using testing::makeGroup;
using testing::Uniforms;

constexpr int kBins = 32;
constexpr int kSamples = 200000;

std::vector<double> histogram(const CpMix& sampler, uint64_t seed) {
  std::vector<double> counts(kBins * kBins, 0.0);
  Uniforms u(seed);
  for (int n = 0; n < kSamples; ++n) {
    CpBlockSample s;
    if (sampler.sample(u.next(), u.next(), &s)) counts[s.j * kBins + s.i] += 1.0;
  }
  return counts;
}

// Pearson chi-square with cells of expected count < 5 pooled into one; the p-value by the
// Wilson-Hilferty normal approximation of the chi-square distribution (accurate for the hundreds
// of degrees of freedom here).
double chiSquarePValue(const std::vector<double>& observed, const std::vector<double>& probability) {
  double stat = 0.0, pooled_obs = 0.0, pooled_exp = 0.0;
  int cells = 0;
  for (size_t n = 0; n < observed.size(); ++n) {
    const double expected = probability[n] * kSamples;
    if (expected < 5.0) {
      pooled_obs += observed[n];
      pooled_exp += expected;
      continue;
    }
    stat += (observed[n] - expected) * (observed[n] - expected) / expected;
    ++cells;
  }
  if (pooled_exp > 0.0) {
    stat += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++cells;
  } else if (pooled_obs > 0.0) {
    return 0.0;  // samples where none are expected
  }
  const double dof = cells - 1;
  const double z = (std::cbrt(stat / dof) - (1.0 - 2.0 / (9.0 * dof))) / std::sqrt(2.0 / (9.0 * dof));
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

std::vector<double> valueProbabilities(const CpMix& mix) {
  std::vector<double> p(kBins * kBins);
  double total = 0.0;
  for (int j = 0; j < kBins; ++j) {
    for (int i = 0; i < kBins; ++i) total += p[j * kBins + i] = mix.value(i, j);
  }
  for (double& v : p) v /= total;
  return p;
}

std::vector<double> pdfProbabilities(const CpMix& mix) {
  std::vector<double> p(kBins * kBins);
  for (int j = 0; j < kBins; ++j) {
    for (int i = 0; i < kBins; ++i) p[j * kBins + i] = mix.pdf(i, j);
  }
  return p;
}

constexpr double kSignificance = 1e-3;

TEST(CpBlockChiSquare, NonnegativeSamplerMatchesPointValues) {
  auto g0 = makeGroup(21, true), g1 = makeGroup(22, true);
  const CpMix mix = makeBlend(*g0, *g1);
  const double p = chiSquarePValue(histogram(mix, 23), valueProbabilities(mix));
  std::printf("non-negative CP sampler vs clamped values: p = %.4g\n", p);
  EXPECT_GT(p, kSignificance);
}

TEST(CpBlockChiSquare, SignedSamplerMatchesItsPdf) {
  auto g0 = makeGroup(24, false), g1 = makeGroup(25, false);
  const CpMix mix = makeBlend(*g0, *g1);
  const double p = chiSquarePValue(histogram(mix, 26), pdfProbabilities(mix));
  const double p_values = chiSquarePValue(histogram(mix, 26), valueProbabilities(mix));
  std::printf("plain CP sampler vs pdf(): p = %.4g; vs clamped values: p = %.4g\n", p, p_values);
  EXPECT_GT(p, kSignificance);
}

TEST(CpBlockChiSquare, MismatchedSamplerFails) {
  auto g0 = makeGroup(27, true), g1 = makeGroup(28, true);
  const CpMix mix = makeBlend(*g0, *g1);
  // Samples from a neighbouring blend (other blocks) judged against this blend's values.
  const CpMix other = makeBlend(*g0, *g1, 4);
  const double p = chiSquarePValue(histogram(other, 29), valueProbabilities(mix));
  std::printf("mismatched sampler: p = %.4g\n", p);
  EXPECT_LT(p, 1e-9);
}

}  // namespace
}  // namespace glintbake::runtime
