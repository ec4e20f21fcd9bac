// SPDX-License-Identifier: Apache-2.0
// Prefix sums of factor columns: entries are the nearest floats to the exact partial sums, and
// range sums of rank-1 terms factorise.
#include <glintbake/bake/tensor/prefix_sums.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace glintbake::bake::tensor {
namespace {

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

TEST(PrefixSums, EntriesAreRoundedExactPartialSums) {
  std::mt19937_64 rng(7);
  const int rows = 32, rank = 5;
  std::vector<float> f(rows * rank);
  for (float& v : f) v = static_cast<float>(uniform(rng) * 2.0 - 0.5);
  const std::vector<float> p = buildPrefixSums(f, rows, rank);
  ASSERT_EQ(p.size(), static_cast<size_t>((rows + 1) * rank));
  for (int r = 0; r < rank; ++r) {
    EXPECT_EQ(p[r], 0.0f);
    long double exact = 0.0;
    for (int i = 0; i < rows; ++i) {
      exact += f[i * rank + r];
      EXPECT_EQ(p[(i + 1) * rank + r], static_cast<float>(exact)) << "row " << i << " column " << r;
    }
  }
}

TEST(PrefixSums, RectangleSumOfRankOneTermFactorises) {
  std::mt19937_64 rng(8);
  const int rows = 16;
  std::vector<float> a(rows), b(rows);
  for (float& v : a) v = static_cast<float>(uniform(rng));
  for (float& v : b) v = static_cast<float>(uniform(rng));
  const std::vector<float> pa = buildPrefixSums(a, rows, 1), pb = buildPrefixSums(b, rows, 1);
  for (int i0 = 0; i0 < rows; i0 += 3) {
    for (int i1 = i0; i1 < rows; i1 += 5) {
      const int j0 = (i0 * 7) % rows, j1 = std::min(rows - 1, j0 + i1 - i0);
      double direct = 0.0;
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) direct += static_cast<double>(a[i]) * b[j];
      }
      const double fast = static_cast<double>(pa[i1 + 1] - pa[i0]) * (pb[j1 + 1] - pb[j0]);
      EXPECT_NEAR(fast, direct, 1e-5 * std::max(1.0, direct));
    }
  }
}

}  // namespace
}  // namespace glintbake::bake::tensor
