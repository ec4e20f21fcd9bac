// The trilinear footprint blend shared by every pyramid-shaped asset (ndf-pyramid, tensor-ndf;
// formats/SPEC.md 10.1): which stored centres a footprint mixes, and with which weights
// (internal to the runtime).
//  - level coordinate: sigma <= sigma_0 uses level 0, sigma >= the top level's sigma the top level,
//    otherwise the two bracketing levels mixed linearly in log(sigma);
//  - within a level, the 4 nearest centres bilinearly; repeating maps wrap the centre grid, clamped
//    maps clamp to the edge centres.
#pragma once

#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/runtime.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace glintbake::runtime {

// Footprint arguments every query accepts: finite, sigma >= 0, position within +-1e15 texels.
inline bool validFootprint(const Footprint& fp) {
  return std::isfinite(fp.x) && std::isfinite(fp.y) && std::isfinite(fp.sigma) && fp.sigma >= 0.0 &&
         std::fabs(fp.x) < 1e15 && std::fabs(fp.y) < 1e15;
}

// Column i and row j of the bin of an R x R NDF image (bin side 2 / res) holding s (row 0 at
// s_y = +1), false outside [-1, 1]^2; ndfBinOf gives the index j * res + i, or -1 outside.
inline bool ndfBinCoords(double sx, double sy, int res, double bin, int* i, int* j) {
  if (!(sx >= -1.0 && sx <= 1.0 && sy >= -1.0 && sy <= 1.0)) return false;
  *i = std::min(res - 1, int((sx + 1.0) / bin));
  *j = std::min(res - 1, int((1.0 - sy) / bin));
  return true;
}
inline int ndfBinOf(double sx, double sy, int res, double bin) {
  int i, j;
  return ndfBinCoords(sx, sy, res, bin, &i, &j) ? j * res + i : -1;
}

// Up to 8 (level, centre, weight) terms; centre = j * grid_width + i on its level. Weights sum to 1.
struct CentreBlend {
  int count = 0;
  int level[8];
  size_t centre[8];
  double weight[8];
};

// Bilinear neighbours of a position along one axis of a level's centre grid (n centres).
inline void blendAxis(double pos, double map_size, double origin, double stride, int n, bool repeat, int* i0, int* i1,
                      double* f) {
  if (repeat) {
    pos -= std::floor(pos / map_size) * map_size;  // into [0, map size)
    const double g = (pos - origin) / stride;
    const double fl = std::floor(g);
    *f = g - fl;
    // pos in [0, map size) puts a in [-1, n - 1]: wrap without integer division in the usual cases.
    const int a = int(fl);
    *i0 = a >= 0 && a < n ? a : (a == -1 ? n - 1 : ((a % n) + n) % n);
    *i1 = *i0 + 1 < n ? *i0 + 1 : 0;
    return;
  }
  const double g = (pos - origin) / stride;
  if (!(g > 0.0)) {
    *i0 = *i1 = 0;
    *f = 0.0;
  } else if (g >= double(n - 1)) {
    *i0 = *i1 = n - 1;
    *f = 0.0;
  } else {
    const double fl = std::floor(g);
    *i0 = int(fl);
    *i1 = *i0 + 1;
    *f = g - fl;
  }
}

inline void blendLevel(const NdfLevelRecord& r, int level, double level_weight, const Footprint& fp, CentreBlend* out) {
  const int gw = int(r.grid_width), gh = int(r.grid_height);
  const bool repeat = r.wrap == 0;
  int x0, x1, y0, y1;
  double fx, fy;
  blendAxis(fp.x, double(r.map_width), r.origin_x, r.stride_x, gw, repeat, &x0, &x1, &fx);
  blendAxis(fp.y, double(r.map_height), r.origin_y, r.stride_y, gh, repeat, &y0, &y1, &fy);
  const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
  const double ws[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  for (int k = 0; k < 4; ++k) {
    if (ws[k] <= 0.0) continue;
    out->level[out->count] = level;
    out->centre[out->count] = size_t(ys[k]) * size_t(gw) + size_t(xs[k]);
    out->weight[out->count] = level_weight * ws[k];
    ++out->count;
  }
}

// levels: any array whose elements have a `rec` member (NdfLevelRecord); level_count >= 1.
template <typename LevelArray>
void blendCentres(const LevelArray& levels, int level_count, const Footprint& fp, CentreBlend* out) {
  out->count = 0;
  const double s0 = levels[0].rec.sigma_texels;
  const double top = levels[level_count - 1].rec.sigma_texels;
  if (!(fp.sigma > s0)) {
    blendLevel(levels[0].rec, 0, 1.0, fp, out);
  } else if (fp.sigma >= top) {
    blendLevel(levels[level_count - 1].rec, level_count - 1, 1.0, fp, out);
  } else {
    int l = 0;
    while (l + 1 < level_count && levels[l + 1].rec.sigma_texels <= fp.sigma) ++l;
    const double sa = levels[l].rec.sigma_texels, sb = levels[l + 1].rec.sigma_texels;
    const double t = std::log(fp.sigma / sa) / std::log(sb / sa);  // linear in log2(sigma)
    blendLevel(levels[l].rec, l, 1.0 - t, fp, out);
    blendLevel(levels[l + 1].rec, l + 1, t, fp, out);
  }
}

}  // namespace glintbake::runtime
