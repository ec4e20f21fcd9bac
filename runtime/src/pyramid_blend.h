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
#include <cstdint>

namespace glintbake::runtime {

// Footprint arguments every query accepts: finite, sigma >= 0, position within +-1e15 texels.
inline bool validFootprint(const Footprint& fp) {
  return std::isfinite(fp.x) && std::isfinite(fp.y) && std::isfinite(fp.sigma) && fp.sigma >= 0.0 &&
         std::fabs(fp.x) < 1e15 && std::fabs(fp.y) < 1e15;
}

// Column i and row j of the bin of an R x R NDF image (bin side 2 / res, inv_bin = res / 2)
// holding s (row 0 at s_y = +1), false outside [-1, 1]^2; ndfBinOf gives the index j * res + i, or
// -1 outside. Every query that locates a bin (pdf, eval, sample's own check) goes through here.
inline bool ndfBinCoords(double sx, double sy, int res, double inv_bin, int* i, int* j) {
  if (!(sx >= -1.0 && sx <= 1.0 && sy >= -1.0 && sy <= 1.0)) return false;
  *i = std::min(res - 1, int((sx + 1.0) * inv_bin));
  *j = std::min(res - 1, int((1.0 - sy) * inv_bin));
  return true;
}
inline int ndfBinOf(double sx, double sy, int res, double inv_bin) {
  int i, j;
  return ndfBinCoords(sx, sy, res, inv_bin, &i, &j) ? j * res + i : -1;
}

// One axis of a level's centre grid, with the divisions of the blend done once at load.
struct BlendAxis {
  double size = 1.0, inv_size = 1.0;      // map texels along the axis and their reciprocal
  double origin = 0.0, inv_stride = 1.0;  // centre 0 and 1 / texels between centres
  int n = 1;                              // centres along the axis
  bool repeat = true;

  void set(double map_size, double origin_texels, double stride, int centres, bool wraps) {
    size = map_size;
    inv_size = 1.0 / map_size;
    origin = origin_texels;
    inv_stride = 1.0 / stride;
    n = centres;
    repeat = wraps;
  }

  // Bilinear neighbours i0, i1 of a position and the weight f of i1.
  void neighbours(double pos, int* i0, int* i1, double* f) const {
    if (repeat) {
      pos -= floorOf(pos * inv_size) * size;  // into [0, map size) up to rounding
      const double g = (pos - origin) * inv_stride;
      const double fl = floorOf(g);
      *f = g - fl;
      // pos in [0, map size) puts fl in [-1, n - 1]: wrap without integer division in the usual
      // cases (rounding at the ends lands in the general branch).
      const int a = int(fl);
      *i0 = a >= 0 && a < n ? a : (a == -1 ? n - 1 : ((a % n) + n) % n);
      *i1 = *i0 + 1 < n ? *i0 + 1 : 0;
      return;
    }
    const double g = (pos - origin) * inv_stride;
    if (!(g > 0.0)) {
      *i0 = *i1 = 0;
      *f = 0.0;
    } else if (g >= double(n - 1)) {
      *i0 = *i1 = n - 1;
      *f = 0.0;
    } else {
      *i0 = int(g);  // g in (0, n - 1): truncation is floor
      *i1 = *i0 + 1;
      *f = g - double(*i0);
    }
  }

  // floor() for |x| well inside the int range (footprints are bounded by validFootprint), without
  // a library call on targets without a rounding instruction; falls back to std::floor outside.
  static double floorOf(double x) {
    if (!(std::fabs(x) < 1e9)) return std::floor(x);
    const double t = double(int64_t(x));
    return t > x ? t - 1.0 : t;
  }
};

// The footprint blend of a pyramid (every per-level constant precomputed): levels and weights
// for a footprint, as formats/SPEC.md 10.1 defines them.
class PyramidBlender {
 public:
  // levels: any array whose elements have a `rec` member (NdfLevelRecord), validated by the
  // loader (strides and sigmas finite and positive, sigmas increasing); 1 <= count <= kMaxNdfLevels.
  template <typename LevelArray>
  void init(const LevelArray& levels, int count) {
    count_ = count;
    for (int l = 0; l < count; ++l) {
      const NdfLevelRecord& r = levels[l].rec;
      const bool repeat = r.wrap == 0;
      Level& g = level_[l];
      g.x.set(double(r.map_width), r.origin_x, r.stride_x, int(r.grid_width), repeat);
      g.y.set(double(r.map_height), r.origin_y, r.stride_y, int(r.grid_height), repeat);
      g.grid_width = size_t(r.grid_width);
      g.sigma = r.sigma_texels;
      g.log_sigma = std::log(r.sigma_texels);
      g.inv_log_step = 0.0;
      if (l > 0) level_[l - 1].inv_log_step = 1.0 / std::log(r.sigma_texels / levels[l - 1].rec.sigma_texels);
    }
  }

  // Calls emit(level, centre, weight) for each of the (at most 8) centres a footprint mixes,
  // centre = j * grid_width + i on its level; the weights sum to 1. Level coordinate: sigma <=
  // sigma_0 uses level 0, sigma >= the top level's sigma the top level, otherwise the two
  // bracketing levels mixed linearly in log(sigma).
  template <typename Emit>
  void blend(const Footprint& fp, Emit&& emit) const {
    if (!(fp.sigma > level_[0].sigma)) {
      blendLevel(0, 1.0, fp, emit);
    } else if (fp.sigma >= level_[count_ - 1].sigma) {
      blendLevel(count_ - 1, 1.0, fp, emit);
    } else {
      int l = 0;
      while (l + 1 < count_ && level_[l + 1].sigma <= fp.sigma) ++l;
      const double t = (std::log(fp.sigma) - level_[l].log_sigma) * level_[l].inv_log_step;
      blendLevel(l, 1.0 - t, fp, emit);
      blendLevel(l + 1, t, fp, emit);
    }
  }

 private:
  struct Level {
    BlendAxis x, y;
    size_t grid_width = 1;
    double sigma = 1.0, log_sigma = 0.0;
    double inv_log_step = 0.0;  // 1 / log(sigma_{l+1} / sigma_l); 0 on the top level
  };

  // Within a level, the 4 nearest centres bilinearly (zero weights skipped).
  template <typename Emit>
  void blendLevel(int l, double level_weight, const Footprint& fp, Emit& emit) const {
    const Level& g = level_[l];
    int x0, x1, y0, y1;
    double fx, fy;
    g.x.neighbours(fp.x, &x0, &x1, &fx);
    g.y.neighbours(fp.y, &y0, &y1, &fy);
    const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
    const double ws[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    for (int k = 0; k < 4; ++k) {
      if (ws[k] > 0.0) emit(l, size_t(ys[k]) * g.grid_width + size_t(xs[k]), level_weight * ws[k]);
    }
  }

  Level level_[kMaxNdfLevels];
  int count_ = 0;
};

}  // namespace glintbake::runtime
