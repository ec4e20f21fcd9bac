// The footprint blend of pyramid-shaped assets (formats/SPEC.md 10.1, "Queries"): which stored
// centres a footprint mixes, and with which weights. The one implementation used by the runtime's
// queries and by the baker's convergence probe (which predicts what the runtime will answer).
//  - level coordinate: sigma <= sigma_0 uses level 0, sigma >= the top level's sigma the top level,
//    otherwise the two bracketing levels mixed linearly in log(sigma);
//  - within a level, the 4 nearest centres bilinearly; repeating maps wrap the centre grid, clamped
//    maps clamp to the edge centres.
// Header-only; no allocation; every per-level constant is computed once by init().
#pragma once

#include <glintbake/format/kinds/ndf_pyramid.h>

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace glintbake::format {

// One axis of a level's centre grid, with the divisions of the blend done once at init.
struct NdfBlendAxis {
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

  // Bilinear neighbours i0, i1 of a position (texels) and the weight f of i1.
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

  // floor() for |x| well inside the int range, without a library call on targets without a
  // rounding instruction; falls back to std::floor outside.
  static double floorOf(double x) {
    if (!(std::fabs(x) < 1e9)) return std::floor(x);
    const double t = double(int64_t(x));
    return t > x ? t - 1.0 : t;
  }
};

class NdfPyramidBlend {
 public:
  // records: `count` level records that passed checkNdfLevelRecord (strides and sigmas finite and
  // positive, sigmas increasing); 1 <= count <= kMaxNdfLevels.
  void init(const NdfLevelRecord* records, int count) {
    count_ = count;
    for (int l = 0; l < count; ++l) {
      const NdfLevelRecord& r = records[l];
      const bool repeat = r.wrap == 0;
      Level& g = level_[l];
      g.x.set(double(r.map_width), r.origin_x, r.stride_x, int(r.grid_width), repeat);
      g.y.set(double(r.map_height), r.origin_y, r.stride_y, int(r.grid_height), repeat);
      g.grid_width = size_t(r.grid_width);
      g.sigma = r.sigma_texels;
      g.log_sigma = std::log(r.sigma_texels);
      g.inv_log_step = 0.0;
      if (l > 0) level_[l - 1].inv_log_step = 1.0 / std::log(r.sigma_texels / records[l - 1].sigma_texels);
    }
  }

  // Calls emit(level, centre, weight) for each of the (at most 8) centres a footprint at (x, y)
  // texels of std sigma mixes, centre = j * grid_width + i on its level; the weights sum to 1.
  template <typename Emit>
  void blend(double x, double y, double sigma, Emit&& emit) const {
    if (!(sigma > level_[0].sigma)) {
      blendLevel(0, 1.0, x, y, emit);
    } else if (sigma >= level_[count_ - 1].sigma) {
      blendLevel(count_ - 1, 1.0, x, y, emit);
    } else {
      int l = 0;
      while (l + 1 < count_ && level_[l + 1].sigma <= sigma) ++l;
      const double t = (std::log(sigma) - level_[l].log_sigma) * level_[l].inv_log_step;
      blendLevel(l, 1.0 - t, x, y, emit);
      blendLevel(l + 1, t, x, y, emit);
    }
  }

  // Within level l, the 4 nearest centres of (x, y) bilinearly, each weight times level_weight
  // (zero weights skipped), in the order (i0, j0), (i1, j0), (i0, j1), (i1, j1).
  template <typename Emit>
  void blendLevel(int l, double level_weight, double x, double y, Emit& emit) const {
    const Level& g = level_[l];
    int x0, x1, y0, y1;
    double fx, fy;
    g.x.neighbours(x, &x0, &x1, &fx);
    g.y.neighbours(y, &y0, &y1, &fy);
    const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
    const double ws[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    for (int k = 0; k < 4; ++k) {
      if (ws[k] > 0.0) emit(l, size_t(ys[k]) * g.grid_width + size_t(xs[k]), level_weight * ws[k]);
    }
  }

 private:
  struct Level {
    NdfBlendAxis x, y;
    size_t grid_width = 1;
    double sigma = 1.0, log_sigma = 0.0;
    double inv_log_step = 0.0;  // 1 / log(sigma_{l+1} / sigma_l); 0 on the top level
  };

  Level level_[kMaxNdfLevels];
  int count_ = 0;
};

}  // namespace glintbake::format
