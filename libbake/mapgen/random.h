// SPDX-License-Identifier: Apache-2.0
// Counter-based random numbers for the map generators: every value is a pure function of
// (seed, stream, index), so results do not depend on thread count, scheduling or the standard
// library (std::normal_distribution differs between implementations; this does not).
#pragma once

#include <glintbake/format/numbers.h>

#include <cmath>
#include <cstdint>

namespace glintbake::bake::mapgen {

// splitmix64 finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mix with good avalanche.
inline uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Independent streams: one per use (noise field, sites, normals, ...), so adding a stream never
// changes the numbers of another.
enum Stream : uint64_t {
  kStreamNoise = 1,
  kStreamScratches = 2,
  kStreamSites = 3,
  kStreamSiteNormals = 4,
};

// A 64-bit random word for (seed, stream, index, draw); `draw` selects one of a few values per index.
inline uint64_t randomBits(uint64_t seed, uint64_t stream, uint64_t index, uint64_t draw = 0) {
  return splitmix64(splitmix64(splitmix64(seed ^ (stream << 56)) ^ index) + draw);
}

// Uniform in [0, 1) with 53 random bits.
inline double uniform01(uint64_t seed, uint64_t stream, uint64_t index, uint64_t draw = 0) {
  return double(randomBits(seed, stream, index, draw) >> 11) * 0x1.0p-53;
}

// Standard normal by the Box-Muller transform (one of the pair; draws 2k and 2k+1 are consumed).
inline double gaussian(uint64_t seed, uint64_t stream, uint64_t index, uint64_t k = 0) {
  const double u1 = 1.0 - uniform01(seed, stream, index, 2 * k);  // (0, 1]: log is finite
  const double u2 = uniform01(seed, stream, index, 2 * k + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
}

}  // namespace glintbake::bake::mapgen
