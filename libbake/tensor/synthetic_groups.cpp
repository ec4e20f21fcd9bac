// SPDX-License-Identifier: Apache-2.0
// NDF-like and exact low-rank group tensors for tests and benchmarks.
#include <glintbake/bake/tensor/synthetic_groups.h>

#include "random.h"

#include <cmath>
#include <vector>

namespace glintbake::bake::tensor {

GroupTensor makeNdfLikeGroup(int bins, int blocks, uint64_t seed, int pool, int lobes_per_block) {
  GLINTBAKE_CHECK(bins >= 1 && bins <= kMaxBlockBins && blocks >= 1 && pool >= 2 && lobes_per_block >= 0);
  SplitMix64 rng(seed);
  struct Lobe {
    double x, y, sigma;
  };
  std::vector<Lobe> lobes(pool);
  for (Lobe& l : lobes) {
    const double x = rng.uniform() * bins, y = rng.uniform() * bins;
    l = {x, y, 0.6 + 1.9 * rng.uniform()};
  }
  GroupTensor t;
  t.bins = bins;
  t.blocks = blocks;
  t.values.assign(static_cast<size_t>(bins) * bins * blocks, 0.0f);
  const double broad_x = bins * (0.3 + 0.4 * rng.uniform());
  const double broad_y = bins * (0.3 + 0.4 * rng.uniform());
  for (int k = 0; k < blocks; ++k) {
    float* block = t.values.data() + static_cast<size_t>(k) * bins * bins;
    const int window = static_cast<int>((static_cast<double>(k) / blocks) * pool / 2);
    for (int n = 0; n < lobes_per_block; ++n) {
      const Lobe& l = lobes[(window + static_cast<int>(rng.uniform() * (pool / 2))) % pool];
      const double amp = 0.2 + rng.uniform();
      const double inv = 1.0 / (2.0 * l.sigma * l.sigma);
      for (int j = 0; j < bins; ++j) {
        for (int i = 0; i < bins; ++i) {
          const double dx = i + 0.5 - l.x, dy = j + 0.5 - l.y;
          block[j * bins + i] += static_cast<float>(amp * std::exp(-(dx * dx + dy * dy) * inv));
        }
      }
    }
    const double broad_amp = 0.02 * rng.uniform();
    for (int j = 0; j < bins; ++j) {
      for (int i = 0; i < bins; ++i) {
        const double dx = (i + 0.5 - broad_x) / bins, dy = (j + 0.5 - broad_y) / bins;
        block[j * bins + i] += static_cast<float>(broad_amp * std::exp(-(dx * dx + dy * dy) * 8.0));
      }
    }
  }
  return t;
}

GroupTensor makeLowRankGroup(int bins, int blocks, int rank, uint64_t seed) {
  GLINTBAKE_CHECK(bins >= 1 && bins <= kMaxBlockBins && blocks >= 1 && rank >= 1);
  SplitMix64 rng(seed);
  std::vector<double> a(static_cast<size_t>(bins) * rank), b(a.size()), c(static_cast<size_t>(blocks) * rank);
  for (double& v : a) v = rng.uniform();
  for (double& v : b) v = rng.uniform();
  for (double& v : c) v = rng.uniform();
  GroupTensor t;
  t.bins = bins;
  t.blocks = blocks;
  t.values.resize(static_cast<size_t>(bins) * bins * blocks);
  for (int k = 0; k < blocks; ++k) {
    for (int j = 0; j < bins; ++j) {
      for (int i = 0; i < bins; ++i) {
        double sum = 0.0;
        for (int r = 0; r < rank; ++r) {
          sum += a[static_cast<size_t>(i) * rank + r] * b[static_cast<size_t>(j) * rank + r] *
                 c[static_cast<size_t>(k) * rank + r];
        }
        t.values[(static_cast<size_t>(k) * bins + j) * bins + i] = static_cast<float>(sum);
      }
    }
  }
  return t;
}

}  // namespace glintbake::bake::tensor
