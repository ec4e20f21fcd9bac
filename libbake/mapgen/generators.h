// SPDX-License-Identifier: Apache-2.0
// The generators behind generateMap(), one per file. Parameters are validated by the caller.
#pragma once

#include <glintbake/bake/mapgen/mapgen.h>

#include <cmath>
#include <cstdint>

namespace glintbake::bake::mapgen {

// Gaussian random surface with per-axis kernel std (texels) and per-axis slope std; see mapgen.h.
NormalMap gaussianSurface(int size, uint64_t seed, double kernel_sigma_x, double kernel_sigma_y, double slope_std_x,
                          double slope_std_y);
NormalMap scratches(const MapParams& params);
NormalMap flakes(const MapParams& params, double cell);

// n = normalize(-dh/dx, -dh/dy_up, 1) for one texel.
inline void slopeToNormal(double dhdx, double dhdy_up, float* n) {
  const double inv = 1.0 / std::sqrt(dhdx * dhdx + dhdy_up * dhdy_up + 1.0);
  n[0] = float(-dhdx * inv);
  n[1] = float(-dhdy_up * inv);
  n[2] = float(inv);
}

}  // namespace glintbake::bake::mapgen
