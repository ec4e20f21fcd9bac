// SPDX-License-Identifier: Apache-2.0
#include <glintbake/bake/ndf/flakes.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <new>
#include <string>

namespace glintbake::bake::ndf {
namespace {

// Texel index with the map's wrap mode (repeat: periodic; clamp: edge texel).
inline int wrapIndex(int i, int n, Wrap wrap) {
  if (wrap == Wrap::kRepeat) {
    int m = i % n;
    return m < 0 ? m + n : m;
  }
  return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

}  // namespace

void interpolateNormal(const NormalMap& map, double ux, double uy, double* nx, double* ny) {
  // Texel centres sit at +0.5, so the interpolation coordinate is u - 0.5.
  const double tx = ux - 0.5, ty = uy - 0.5;
  const double fx0 = std::floor(tx), fy0 = std::floor(ty);
  const double fx = tx - fx0, fy = ty - fy0;
  const int x0 = int(fx0), y0 = int(fy0);
  const int xa = wrapIndex(x0, map.width, map.wrap), xb = wrapIndex(x0 + 1, map.width, map.wrap);
  const int ya = wrapIndex(y0, map.height, map.wrap), yb = wrapIndex(y0 + 1, map.height, map.wrap);
  const float* n00 = map.at(xa, ya);
  const float* n10 = map.at(xb, ya);
  const float* n01 = map.at(xa, yb);
  const float* n11 = map.at(xb, yb);
  const double w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
  *nx = w00 * n00[0] + w10 * n10[0] + w01 * n01[0] + w11 * n11[0];
  *ny = w00 * n00[1] + w10 * n10[1] + w01 * n01[1] + w11 * n11[1];
}

Result<FlakeSet> buildFlakes(const NormalMap& map, int rate) {
  if (rate < 1 || rate > kMaxFlakeRate) {
    return makeError(ErrorCode::kBadArgument, "rate must be in [1, " + std::to_string(kMaxFlakeRate) + "]");
  }
  if (map.width < 1 || map.height < 1 || map.normals.size() != size_t(map.width) * size_t(map.height) * 3) {
    return makeError(ErrorCode::kInvalidInput, "normal map is empty or inconsistent");
  }
  FlakeSet set;
  set.map_width = map.width;
  set.map_height = map.height;
  set.rate = rate;
  set.wrap = map.wrap;
  set.grid_width = map.width * rate;
  set.grid_height = map.height * rate;
  set.step = 1.0 / rate;
  set.area = set.step * set.step;
  set.sigma_h = set.step * 1.5 / std::sqrt(12.0);
  const size_t count = size_t(set.grid_width) * size_t(set.grid_height);
  if (count > std::numeric_limits<size_t>::max() / (kFlakeFloats * sizeof(float)) / 2) {
    return makeError(ErrorCode::kRuntime, "too many flakes");
  }
  try {
    set.data.resize(count * kFlakeFloats);
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating " + std::to_string(count) + " flakes");
  }

  // Each flake is independent, so the parallel loop is deterministic.
  tbb::parallel_for(tbb::blocked_range<int>(0, set.grid_height), [&](const tbb::blocked_range<int>& rows) {
    for (int gy = rows.begin(); gy != rows.end(); ++gy) {
      const double uy = set.positionY(gy);
      for (int gx = 0; gx < set.grid_width; ++gx) {
        const double ux = set.positionX(gx);
        double nx, ny, xp, yp, xm, ym, xd, yd, xu, yu;
        interpolateNormal(map, ux, uy, &nx, &ny);
        interpolateNormal(map, ux + 1.0, uy, &xp, &yp);
        interpolateNormal(map, ux - 1.0, uy, &xm, &ym);
        interpolateNormal(map, ux, uy + 1.0, &xd, &yd);
        interpolateNormal(map, ux, uy - 1.0, &xu, &yu);
        float* f = &set.data[(size_t(gy) * size_t(set.grid_width) + size_t(gx)) * kFlakeFloats];
        f[0] = float(nx);
        f[1] = float(ny);
        f[2] = float(0.5 * (xp - xm));  // d n_x / d u_x
        f[3] = float(0.5 * (yp - ym));  // d n_y / d u_x
        f[4] = float(0.5 * (xd - xu));  // d n_x / d u_y
        f[5] = float(0.5 * (yd - yu));  // d n_y / d u_y
      }
    }
  });
  return set;
}

}  // namespace glintbake::bake::ndf
