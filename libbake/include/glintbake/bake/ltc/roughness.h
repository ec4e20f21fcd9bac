// SPDX-License-Identifier: Apache-2.0
// Per-texel roughness mips of a normal map for LTC shading (Tao et al. 2021): each mip level holds
// the overall alpha of the micro-scale alpha and the meso-scale alpha implied by the length |b| of
// that level's unnormalised averaged normal.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/ltc/multiscale.h>
#include <glintbake/bake/result.h>
#include <glintbake/format/container.h>

#include <string>
#include <vector>

namespace glintbake::bake::ltc {

struct RoughnessOptions {
  double alpha_micro = 0.1;  // micro-scale GGX alpha, [0, 1]
  bool exact_meso = false;   // invert eq. 4 exactly instead of using the rational fit
  MesoFit meso = defaultMesoFit();
  CombineFit combine = defaultCombineFit();
};

struct RoughnessLevel {
  int width = 0;
  int height = 0;
  std::vector<float> alpha;        // overall alpha per texel, row-major, row 0 at the top
  std::vector<float> mean_length;  // |b| per texel
};

// Level 0 has the map's size; each next level halves width and height (rounding up) with a 2x2 box
// filter of the unnormalised averaged normals (odd edges average the texels that exist), down to
// 1 x 1. Thread-safe; levels are computed in parallel, bit-identically for any thread count.
Result<std::vector<RoughnessLevel>> bakeRoughness(const NormalMap& map, const RoughnessOptions& options);

// Adds one section per level to an open writer of a roughness asset (formats/SPEC.md 10.3: type
// 64, key = level, width x height x 1 image sections). kIo on a writer failure.
BakeStatus writeRoughnessSections(const std::vector<RoughnessLevel>& levels, format::Writer& writer);

// Writes the levels as one tiled, mipmapped single-channel float EXR (channel "Y"), atomically and
// byte-reproducibly (no capture date).
BakeStatus writeRoughnessExr(const std::vector<RoughnessLevel>& levels, const std::string& path);

}  // namespace glintbake::bake::ltc
