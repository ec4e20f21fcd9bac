// SPDX-License-Identifier: Apache-2.0
// The flake model shared by the runtime's exact and clustered evaluators (formats/SPEC.md 10.5;
// internal to the runtime): flake k at fine position u_k has normal n_k, the bilinear interpolation
// of the texels' (n_x, n_y) at u_k, and Jacobian J_k, central differences of that interpolant one
// texel on each side.
#pragma once

#include <glintbake/runtime/runtime.h>

#include "../query_args.h"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace glintbake::runtime::flakes {

// Texel index with a wrap mode (repeat: modulo; clamp: nearest edge texel).
inline int64_t wrapIndex(int64_t i, int64_t size, bool repeat) {
  if (repeat) {
    const int64_t m = i % size;
    return m < 0 ? m + size : m;
  }
  return i < 0 ? 0 : (i >= size ? size - 1 : i);
}

// Bilinear interpolation of the texels' (n_x, n_y) (row-major pairs, w x h) at u (texel centres
// at +0.5).
inline void interpolate(const float* normals, int w, int h, bool repeat, double ux, double uy, double out[2]) {
  const double px = ux - 0.5, py = uy - 0.5;
  const double fx0 = std::floor(px), fy0 = std::floor(py);
  const double tx = px - fx0, ty = py - fy0;
  const int64_t x0 = int64_t(fx0), y0 = int64_t(fy0);
  const int64_t xs[2] = {wrapIndex(x0, w, repeat), wrapIndex(x0 + 1, w, repeat)};
  const int64_t ys[2] = {wrapIndex(y0, h, repeat), wrapIndex(y0 + 1, h, repeat)};
  const double wx[2] = {1.0 - tx, tx}, wy[2] = {1.0 - ty, ty};
  double nx = 0.0, ny = 0.0;
  for (int b = 0; b < 2; ++b) {
    for (int a = 0; a < 2; ++a) {
      const float* t = normals + (size_t(ys[b]) * size_t(w) + size_t(xs[a])) * 2;
      nx += wx[a] * wy[b] * double(t[0]);
      ny += wx[a] * wy[b] * double(t[1]);
    }
  }
  out[0] = nx;
  out[1] = ny;
}

// Normal and Jacobian {dnx/dux, dnx/duy, dny/dux, dny/duy} of the flake at u.
inline void flakeAt(const float* normals, int w, int h, bool repeat, double ux, double uy, float n[2], float j[4]) {
  double c[2], right[2], left[2], down[2], up[2];
  interpolate(normals, w, h, repeat, ux, uy, c);
  interpolate(normals, w, h, repeat, ux + 1.0, uy, right);
  interpolate(normals, w, h, repeat, ux - 1.0, uy, left);
  interpolate(normals, w, h, repeat, ux, uy + 1.0, down);
  interpolate(normals, w, h, repeat, ux, uy - 1.0, up);
  n[0] = float(c[0]);
  n[1] = float(c[1]);
  j[0] = float((right[0] - left[0]) * 0.5);
  j[1] = float((down[0] - up[0]) * 0.5);
  j[2] = float((right[1] - left[1]) * 0.5);
  j[3] = float((down[1] - up[1]) * 0.5);
}

// Flakes per side of a tile of the exact flakes' hierarchy, and of a tile of the clustered lobes'
// level 1 (level 0's tiles of 4 flakes, merged in twos): the two grids coincide.
constexpr int kTileFlakes = 8;

// The tiles of a cut through the clustered lobes that the exact flakes answer (lobe_ndf.cpp): the
// tiles of kTileFlakes flakes whose nearest point lies within sqrt(limit2) texels of the footprint
// centre. Both evaluators decide it with tileGap, so that they agree on every tile to the bit.
struct TileCut {
  double side;    // tile side, texels
  double limit2;  // squared distance below which a tile is inside
};

// The offset u - origin of tile (tx, ty) of side `side` (bx, by) and the distance from u to the
// tile along each axis (dx, dy; 0 inside), u relative to the origin of a periodic image of the map.
inline void tileGap(double ux, double uy, int64_t tx, int64_t ty, double side, double* bx, double* by, double* dx,
                    double* dy) {
  *bx = ux - double(tx) * side;
  *by = uy - double(ty) * side;
  *dx = *bx < 0.0 ? -*bx : (*bx > side ? *bx - side : 0.0);
  *dy = *by < 0.0 ? -*by : (*by > side ? *by - side : 0.0);
}

// Query arguments shared by the flake and lobe evaluators.
inline bool inSquare(const SPoint& s) { return s.x >= -1.0 && s.x <= 1.0 && s.y >= -1.0 && s.y <= 1.0; }

}  // namespace glintbake::runtime::flakes
