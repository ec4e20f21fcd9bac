// SPDX-License-Identifier: Apache-2.0
// Flakes of a normal map per the flake model of formats/SPEC.md (see flakes.h).
#include <glintbake/reference/flakes.h>

#include <glintbake/bake/result.h>

#include <cmath>
#include <cstdint>

namespace glintbake::reference {
namespace {

// Texel index along one axis with the map's wrap mode applied.
int64_t wrapIndex(int64_t i, int64_t size, bake::Wrap wrap) {
  if (wrap == bake::Wrap::kRepeat) {
    const int64_t m = i % size;
    return m < 0 ? m + size : m;
  }
  return i < 0 ? 0 : (i >= size ? size - 1 : i);
}

}  // namespace

void interpolateNormal(const bake::NormalMap& map, double ux, double uy, double n_out[2]) {
  GLINTBAKE_DCHECK(map.width > 0 && map.height > 0);
  // Texel centres sit at +0.5: shift so that integer coordinates are centres.
  const double px = ux - 0.5;
  const double py = uy - 0.5;
  const double fx0 = std::floor(px);
  const double fy0 = std::floor(py);
  const double tx = px - fx0;
  const double ty = py - fy0;
  const int64_t x0 = int64_t(fx0);
  const int64_t y0 = int64_t(fy0);
  const int64_t xs[2] = {wrapIndex(x0, map.width, map.wrap), wrapIndex(x0 + 1, map.width, map.wrap)};
  const int64_t ys[2] = {wrapIndex(y0, map.height, map.wrap), wrapIndex(y0 + 1, map.height, map.wrap)};
  const double wx[2] = {1.0 - tx, tx};
  const double wy[2] = {1.0 - ty, ty};
  double nx = 0.0;
  double ny = 0.0;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const float* texel = map.at(int(xs[i]), int(ys[j]));
      const double w = wx[i] * wy[j];
      nx += w * double(texel[0]);
      ny += w * double(texel[1]);
    }
  }
  n_out[0] = nx;
  n_out[1] = ny;
}

FlakeSet buildFlakes(const bake::NormalMap& map, int rate) {
  GLINTBAKE_CHECK(rate >= 1 && rate <= kMaxRate);
  GLINTBAKE_CHECK(map.width > 0 && map.height > 0);
  GLINTBAKE_CHECK(map.normals.size() == size_t(map.width) * size_t(map.height) * 3);

  FlakeSet set;
  set.width = map.width;
  set.height = map.height;
  set.wrap = map.wrap;
  set.rate = rate;
  set.step = 1.0 / double(rate);
  set.area = set.step * set.step;
  // A box of side `step` has std step / sqrt(12); the factor 1.5 widens the flakes so that
  // neighbours overlap smoothly (Yan et al. 2016, section 4).
  set.sigma_h = set.step * 1.5 / std::sqrt(12.0);

  const int fine_w = set.fineWidth();
  const int fine_h = set.fineHeight();
  set.flakes.resize(size_t(fine_w) * size_t(fine_h));
  for (int fr = 0; fr < fine_h; ++fr) {
    for (int fc = 0; fc < fine_w; ++fc) {
      Flake& f = set.flakes[size_t(fr) * size_t(fine_w) + size_t(fc)];
      f.u[0] = (double(fc) + 0.5) / double(rate);
      f.u[1] = (double(fr) + 0.5) / double(rate);
      interpolateNormal(map, f.u[0], f.u[1], f.n);
      // Central differences of the interpolant, one texel on each side.
      double right[2], left[2], down[2], up[2];
      interpolateNormal(map, f.u[0] + 1.0, f.u[1], right);
      interpolateNormal(map, f.u[0] - 1.0, f.u[1], left);
      interpolateNormal(map, f.u[0], f.u[1] + 1.0, down);
      interpolateNormal(map, f.u[0], f.u[1] - 1.0, up);
      f.jacobian[0] = (right[0] - left[0]) * 0.5;  // dnx/dux
      f.jacobian[1] = (down[0] - up[0]) * 0.5;     // dnx/duy
      f.jacobian[2] = (right[1] - left[1]) * 0.5;  // dny/dux
      f.jacobian[3] = (down[1] - up[1]) * 0.5;     // dny/duy
    }
  }
  return set;
}

}  // namespace glintbake::reference
