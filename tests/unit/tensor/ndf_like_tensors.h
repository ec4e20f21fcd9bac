// Procedural NDF-like group tensors for the CP tests: K blocks of B x B bins, each a sum of sharp
// Gaussian lobes (glint peaks of 0.6-2.5 bins) whose positions come from a pool shared by the
// group, like the blocks of neighbouring footprints, plus a faint broad lobe. Seeded and portable.
#pragma once

#include <glintbake/bake/tensor/cp_decomposition.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace glintbake::bake::tensor::testing {

class TestRng {
 public:
  explicit TestRng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  uint64_t state_;
};

inline GroupTensor makeNdfLikeTensor(int bins, int blocks, uint64_t seed, int pool = 48, int lobes_per_block = 10) {
  TestRng rng(seed);
  struct Lobe { double x, y, sigma; };
  std::vector<Lobe> lobes(pool);
  for (Lobe& l : lobes) l = {rng.uniform() * bins, rng.uniform() * bins, 0.6 + 1.9 * rng.uniform()};
  GroupTensor t;
  t.bins = bins;
  t.blocks = blocks;
  t.values.assign(static_cast<size_t>(bins) * bins * blocks, 0.0f);
  const double broad_x = bins * (0.3 + 0.4 * rng.uniform()), broad_y = bins * (0.3 + 0.4 * rng.uniform());
  for (int k = 0; k < blocks; ++k) {
    float* block = t.values.data() + static_cast<size_t>(k) * bins * bins;
    // Neighbouring blocks draw from a drifting window of the pool.
    const int window = static_cast<int>((static_cast<double>(k) / blocks) * pool / 2);
    for (int n = 0; n < lobes_per_block; ++n) {
      const Lobe& l = lobes[(window + static_cast<int>(rng.uniform() * pool / 2)) % pool];
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

// An exact rank-R tensor with positive random factors.
inline GroupTensor makeLowRankTensor(int bins, int blocks, int rank, uint64_t seed) {
  TestRng rng(seed);
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
        for (int r = 0; r < rank; ++r) sum += a[i * rank + r] * b[j * rank + r] * c[k * rank + r];
        t.values[(static_cast<size_t>(k) * bins + j) * bins + i] = static_cast<float>(sum);
      }
    }
  }
  return t;
}

}  // namespace glintbake::bake::tensor::testing
