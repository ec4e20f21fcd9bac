// SPDX-License-Identifier: Apache-2.0
// Importance sampling of the reference P-NDF, for chi-square tests of the evaluator and of every
// fast sampler.
//
// The P-NDF is the footprint-weighted mixture of the flakes' lobes (pndf.h). Drawing a position
// u ~ G_P, then a flake by its spatial Gaussian at u, then a normal from the flake's conditional
// normal distribution is equivalent to the exact mixture form used here: choose the lobe k with
// probability weight_k / sum(weight), then s ~ N(mu_k, C_k). The density of the samples is
// therefore exactly evalPndf(s) / footprintWeight().
#pragma once

#include <glintbake/reference/pndf.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace glintbake::reference {

struct PndfSample {
  double sx;  // s-plane point (not restricted to the unit disk: lobes near the rim spill over)
  double sy;
};

// A stream of samples of one footprint's P-NDF (for sample counts too large to hold in memory).
// Construction gathers the lobes (pndf.h, footprintLobes) and their running weight sums.
// Not thread-safe (holds the generator state); use one sampler per thread.
class PndfSampler {
 public:
  // Requires fp.sigma > 0 and sigma_r > 0 (aborts otherwise).
  PndfSampler(const FlakeSet& set, const Footprint& fp, double sigma_r, uint64_t seed);
  PndfSampler(PndfSampler&&) noexcept;
  PndfSampler& operator=(PndfSampler&&) noexcept;
  ~PndfSampler();

  // False when no lobe has positive weight (a clamp footprint far outside the map): next() must
  // not be called then.
  bool valid() const;
  size_t lobeCount() const;
  // Sum of the lobe weights (footprintWeight): the sample density is evalPndf / totalWeight.
  double totalWeight() const;
  PndfSample next();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// `count` samples of the footprint's P-NDF (the first `count` of PndfSampler's stream), deterministic for a seed on every platform with IEEE
// double arithmetic and the same libm: PCG32 (O'Neill 2014) random numbers, Box-Muller normals, no
// std:: distributions. Requires fp.sigma > 0, sigma_r > 0 and at least one lobe with positive
// weight (a footprint that sees flakes; returns an empty vector otherwise).
// Memory: count * 16 bytes plus the lobes. Thread-safe; uses one thread.
std::vector<PndfSample> samplePndf(const FlakeSet& set, const Footprint& fp, double sigma_r, size_t count,
                                   uint64_t seed);

}  // namespace glintbake::reference
