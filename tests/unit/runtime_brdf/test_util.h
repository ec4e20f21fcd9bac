// SPDX-License-Identifier: Apache-2.0
// Shared helpers of the BRDF tests: a counter-based generator and a chi-square test of a
// direction sampler against its density on the sphere (Mitsuba 3's ChiSquareTest, simplified).
#pragma once

#include <glintbake/format/numbers.h>
#include <glintbake/runtime/brdf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

namespace glintbake::runtime::testing {

// splitmix64: a tiny deterministic generator of uniforms in [0, 1).
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  double next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_;
};

inline Vec3 sphericalDirection(double z, double phi) {
  const double r = std::sqrt(std::fmax(0.0, 1.0 - z * z));
  return Vec3{r * std::cos(phi), r * std::sin(phi), z};
}

struct ChiSquareResult {
  double statistic = 0.0;
  int dof = 0;
  double threshold = 0.0;  // critical value at significance 1e-3 (Wilson-Hilferty)
  double sampled_mass = 0.0;
  double integrated_mass = 0.0;
};

// Histograms `count` draws of `sample` (returning false for a discarded draw) over z x phi cells
// of equal solid angle, integrates `pdf` over each cell with a sub-grid, merges cells with an
// expected count below 5 and returns the chi-square statistic and its threshold.
inline ChiSquareResult chiSquare(const std::function<bool(double, double, Vec3*)>& sample,
                                 const std::function<double(const Vec3&)>& pdf, int count, uint64_t seed,
                                 int z_bins = 24, int phi_bins = 48, int sub = 8) {
  std::vector<double> observed(size_t(z_bins) * phi_bins, 0.0), expected(observed.size(), 0.0);
  Rng rng(seed);
  int kept = 0;
  for (int n = 0; n < count; ++n) {
    const double u1 = rng.next(), u2 = rng.next();
    Vec3 w;
    if (!sample(u1, u2, &w)) continue;
    ++kept;
    double phi = std::atan2(w.y, w.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    const int iz = std::min(z_bins - 1, std::max(0, int((w.z + 1.0) * 0.5 * z_bins)));
    const int ip = std::min(phi_bins - 1, std::max(0, int(phi / (2.0 * kPi) * phi_bins)));
    observed[size_t(iz) * phi_bins + ip] += 1.0;
  }
  const double cell_area = 4.0 * kPi / (double(z_bins) * phi_bins * sub * sub);
  ChiSquareResult r;
  for (int iz = 0; iz < z_bins; ++iz) {
    for (int ip = 0; ip < phi_bins; ++ip) {
      double sum = 0.0;
      for (int a = 0; a < sub; ++a) {
        for (int b = 0; b < sub; ++b) {
          const double z = -1.0 + (iz + (a + 0.5) / sub) * 2.0 / z_bins;
          const double phi = (ip + (b + 0.5) / sub) * 2.0 * kPi / phi_bins;
          sum += pdf(sphericalDirection(z, phi));
        }
      }
      expected[size_t(iz) * phi_bins + ip] = sum * cell_area * count;
      r.integrated_mass += sum * cell_area;
    }
  }
  r.sampled_mass = double(kept) / count;
  // Merge low-expectation cells into one pooled cell.
  double pooled_obs = 0.0, pooled_exp = 0.0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5.0) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      continue;
    }
    const double d = observed[i] - expected[i];
    r.statistic += d * d / expected[i];
    ++r.dof;
  }
  if (pooled_exp > 0.0) {
    const double d = pooled_obs - pooled_exp;
    r.statistic += d * d / std::fmax(pooled_exp, 5.0);
    ++r.dof;
  }
  r.dof = std::max(1, r.dof - 1);
  // Wilson-Hilferty: chi2_p ~ k (1 - 2/(9k) + z_p sqrt(2/(9k)))^3, z for p = 1e-3 is 3.09.
  const double k = r.dof;
  const double t = 1.0 - 2.0 / (9.0 * k) + 3.09 * std::sqrt(2.0 / (9.0 * k));
  r.threshold = k * t * t * t;
  return r;
}

}  // namespace glintbake::runtime::testing
