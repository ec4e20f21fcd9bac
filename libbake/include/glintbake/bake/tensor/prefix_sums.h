// SPDX-License-Identifier: Apache-2.0
// 1D summed-area tables of CP factor columns: the range sum of a rank-1 term over a rectangle of
// bins is the product of two 1D range sums, so a B x B rectangle average of a CP block costs O(R)
// (Deng et al. 2022, sec. 4.3).
#pragma once

#include <vector>

namespace glintbake::bake::tensor {

// Prefix sums of every column of a row-major rows x rank factor matrix: (rows + 1) x rank,
// row-major, P[t * rank + r] = sum_{i < t} F[i * rank + r] (P[0] = 0). Accumulated in double and
// rounded once per entry, so each entry is the float nearest the exact partial sum; the tables
// are per block (rows = B, typically 32), which keeps differences of entries precise in float.
// Requires factor.size() == rows * rank. Thread-safe.
std::vector<float> buildPrefixSums(const std::vector<float>& factor, int rows, int rank);

}  // namespace glintbake::bake::tensor
