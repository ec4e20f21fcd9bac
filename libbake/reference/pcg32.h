// SPDX-License-Identifier: Apache-2.0
// Private: the PCG32 generator (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient
// Statistically Good Algorithms for Random Number Generation", pcg32 = XSH-RR 64/32), and the
// portable uniform and normal variates built on it. Same sequence on every platform.
#pragma once

#include <glintbake/format/numbers.h>

#include <cmath>
#include <cstdint>

namespace glintbake::reference::detail {

class Pcg32 {
 public:
  Pcg32(uint64_t seed, uint64_t stream) {
    inc_ = (stream << 1u) | 1u;
    next();
    state_ += seed;
    next();
  }

  uint32_t next() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform in [0, 1) with 53 random bits.
  double uniform() {
    const uint64_t a = next() >> 5;  // 27 bits
    const uint64_t b = next() >> 6;  // 26 bits
    return double((a << 26) | b) * (1.0 / 9007199254740992.0);
  }

  // Two independent standard normals (Box-Muller).
  void normalPair(double* z0, double* z1) {
    const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double theta = kTwoPi * u2;
    *z0 = r * std::cos(theta);
    *z1 = r * std::sin(theta);
  }

 private:
  uint64_t state_ = 0;
  uint64_t inc_ = 0;
};

}  // namespace glintbake::reference::detail
