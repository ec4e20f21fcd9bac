// SPDX-License-Identifier: Apache-2.0
// A small portable generator for the seeded parts of the CP decomposition (random starts and the
// range finder): SplitMix64 (Steele et al. 2014), identical on every platform.
#pragma once

#include <glintbake/format/numbers.h>

#include <cmath>
#include <cstdint>

namespace glintbake::bake::tensor {

class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}

  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  // Standard normal by Box-Muller (one value per call; the pair's second half is discarded so the
  // stream position depends only on the call count).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace glintbake::bake::tensor
