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
#include <vector>

namespace glintbake::reference {

struct PndfSample {
  double sx;  // s-plane point (not restricted to the unit disk: lobes near the rim spill over)
  double sy;
};

// `count` samples of the footprint's P-NDF, deterministic for a seed on every platform with IEEE
// double arithmetic and the same libm: PCG32 (O'Neill 2014) random numbers, Box-Muller normals, no
// std:: distributions. Requires fp.sigma > 0, sigma_r > 0 and at least one lobe with positive
// weight (a footprint that sees flakes; returns an empty vector otherwise).
// Memory: count * 16 bytes plus the lobes. Thread-safe; uses one thread.
std::vector<PndfSample> samplePndf(const FlakeSet& set, const Footprint& fp, double sigma_r, size_t count,
                                   uint64_t seed);

}  // namespace glintbake::reference
