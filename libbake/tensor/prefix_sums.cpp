// SPDX-License-Identifier: Apache-2.0
// Per-block summed-area tables of CP factor columns.
#include <glintbake/bake/tensor/prefix_sums.h>

#include <glintbake/bake/result.h>

namespace glintbake::bake::tensor {

std::vector<float> buildPrefixSums(const std::vector<float>& factor, int rows, int rank) {
  GLINTBAKE_CHECK(rows >= 0 && rank >= 0 && factor.size() == static_cast<size_t>(rows) * rank);
  std::vector<float> out(static_cast<size_t>(rows + 1) * rank, 0.0f);
  for (int r = 0; r < rank; ++r) {
    double sum = 0.0;
    for (int i = 0; i < rows; ++i) {
      sum += factor[static_cast<size_t>(i) * rank + r];
      out[static_cast<size_t>(i + 1) * rank + r] = static_cast<float>(sum);
    }
  }
  return out;
}

}  // namespace glintbake::bake::tensor
