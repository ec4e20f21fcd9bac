// SPDX-License-Identifier: Apache-2.0
// Flakes of a normal map: the 4D Gaussian elements of Yan et al. 2016 ("Position-Normal
// Distributions for Efficient Rendering of Specular Microstructure"), built for the fast NDF path.
//
// The flake model is normative (formats/SPEC.md, "Flake model"); the reference evaluator builds the
// same elements independently. With rate r sub-samples per texel side:
//  - flake (gx, gy) of the virtual grid (width*r x height*r) sits at u = ((gx + 0.5)/r, (gy + 0.5)/r)
//    texels (texel centres at +0.5, y grows downwards);
//  - its normal n = (n_x, n_y) is the bilinear interpolation of the texels' (n_x, n_y) at u, texel
//    centres at +0.5, neighbours fetched with the map's wrap mode, not renormalised;
//  - its Jacobian J = d(n_x, n_y)/du by central differences of that interpolant with a step of one
//    texel: column 0 = (n(u + (1,0)) - n(u - (1,0))) / 2, column 1 = (n(u + (0,1)) - n(u - (0,1))) / 2;
//  - area A = step^2, spatial std sigma_h = step * 1.5 / sqrt(12), step = 1/r.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/result.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glintbake::bake::ndf {

// Floats stored per flake: n_x, n_y, J00, J10, J01, J11 (J column-major: J(row, col), rows = n_x/n_y,
// cols = u_x/u_y).
constexpr int kFlakeFloats = 6;

// All flakes of one map, in row-major order of the virtual grid. Immutable after construction;
// concurrent reads are safe. Memory: 24 bytes per flake (rate^2 flakes per texel).
struct FlakeSet {
  int map_width = 0;   // texels
  int map_height = 0;  // texels
  int rate = 1;        // sub-samples per texel side
  Wrap wrap = Wrap::kRepeat;
  int grid_width = 0;       // map_width * rate
  int grid_height = 0;      // map_height * rate
  double step = 1.0;        // texels between flakes (1 / rate)
  double area = 1.0;        // step^2, texel^2
  double sigma_h = 0.0;     // spatial std of a flake, texels
  std::vector<float> data;  // kFlakeFloats per flake

  const float* flake(int gx, int gy) const {
    return &data[(size_t(gy) * size_t(grid_width) + size_t(gx)) * kFlakeFloats];
  }
  // Centre of flake (gx, gy) in texels; gx, gy may lie outside the grid (periodic images).
  double positionX(int64_t gx) const { return (double(gx) + 0.5) * step; }
  double positionY(int64_t gy) const { return (double(gy) + 0.5) * step; }
};

// Largest accepted rate (flakes per texel side).
constexpr int kMaxFlakeRate = 16;

// Builds the flakes of a map. rate in [1, kMaxFlakeRate]; the map must be at least 1x1 with finite
// normals (ingest guarantees it). Runs in parallel (TBB); the result does not depend on the thread
// count. Fails with kBadArgument on a bad rate and kRuntime if the flake count would not fit in memory.
Result<FlakeSet> buildFlakes(const NormalMap& map, int rate);

// The (n_x, n_y) interpolant of the flake model at position (ux, uy) texels, with the map's wrap
// mode. Exposed for tests.
void interpolateNormal(const NormalMap& map, double ux, double uy, double* nx, double* ny);

}  // namespace glintbake::bake::ndf
