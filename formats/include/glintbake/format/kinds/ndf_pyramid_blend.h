// SPDX-License-Identifier: Apache-2.0
// The footprint blend of pyramid-shaped assets (formats/SPEC.md 10.1, "Queries"): which stored
// centres a footprint mixes, and with which weights. The one implementation used by the runtime's
// queries and by the baker's convergence probe (which predicts what the runtime will answer).
//
// A stored image of level l is the NDF of a footprint N(c, sigma_l^2) at centre c. A footprint
// N(u, sigma^2) with sigma > sigma_l is that footprint convolved with N(0, tau^2),
// tau^2 = sigma^2 - sigma_l^2, so its NDF is the tau-Gaussian-weighted mean of level-l images over
// the centres (exactly, in the limit of dense centres). blend() uses that deconvolution:
//  - sigma <= sigma_0: the 4 nearest centres of level 0 bilinearly;
//  - above: on the finest level whose spread q = tau' / stride stays within kMaxSpread, each centre
//    weighted by the Gaussian of std tau' integrated against the centre's bilinear hat (a tent of
//    one stride), tau'^2 = tau^2 - stride^2 / 6 taking out the variance the tent adds (tau' = 0
//    is plain bilinear interpolation); as q approaches kMaxSpread the next level is blended in, so
//    the weights are continuous in sigma. Above the top level's reach the spread is held at
//    kMaxSpread (a clamp).
// Repeating maps wrap the centre grid, clamped maps clamp to the edge centres. Every weight is
// separable (x times y); the weights sum to 1 up to the truncation at 3.5 tau' (below 1e-3).
// Header-only; no allocation; every per-level constant is computed once by init().
#pragma once

#include <glintbake/format/kinds/ndf_pyramid.h>

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace glintbake::format {

// Most centres per axis of a top level that the blend spreads to any width (a repeating map's whole
// grid, see gaussianLevel); the baker's automatic level count stops only at a grid this small.
constexpr int kWholeGridAxis = 16;
// Most centres blend() emits per axis of one level (the 2 (3.5 q + 1) + 2 a spread of
// NdfPyramidBlend::kMaxSpread can reach, rounded up) and for one footprint (two levels).
constexpr int kMaxBlendAxis = 22;
constexpr int kMaxBlendCentres = 2 * kMaxBlendAxis * kMaxBlendAxis;

// F(z) = z Phi(z) + phi(z) (the Gaussian's CDF integrated once), whose second differences are the
// blend's tent-integrated weights: a cubic Hermite interpolant of F and F' = Phi between nodes
// 1/64 apart on [-8, 8] (error below max |F''''| h^4 / 384 = 7e-11), 0 below and z above (F
// differs from them by less than 1e-16 there). Four multiply-adds instead of erfc and exp: the
// weights were most of a pyramid query's time.
class NdfRamp {
 public:
  static constexpr int kPerUnit = 64;
  static constexpr double kReach = 8.0;
  static constexpr int kNodes = int(2 * kReach) * kPerUnit + 1;

  static const NdfRamp& table() {
    static const NdfRamp t;
    return t;
  }
  double operator()(double z) const {
    if (!(z > -kReach)) return 0.0;
    if (z >= kReach) return z;
    const double u = (z + kReach) * kPerUnit;
    int i = int(u);
    if (i > kNodes - 2) i = kNodes - 2;
    const double t = u - double(i), t2 = t * t, t3 = t2 * t;
    const double h00 = 2.0 * t3 - 3.0 * t2 + 1.0, h10 = t3 - 2.0 * t2 + t;
    const double h01 = -2.0 * t3 + 3.0 * t2, h11 = t3 - t2;
    constexpr double kStep = 1.0 / kPerUnit;
    return h00 * f_[i] + h01 * f_[i + 1] + kStep * (h10 * d_[i] + h11 * d_[i + 1]);
  }

 private:
  NdfRamp() {
    for (int i = 0; i < kNodes; ++i) {
      const double z = -kReach + double(i) / kPerUnit;
      const double cdf = 0.5 * std::erfc(-z * 0.70710678118654752);
      f_[i] = z * cdf + 0.39894228040143267794 * std::exp(-0.5 * z * z);
      d_[i] = cdf;
    }
  }
  double f_[kNodes], d_[kNodes];
};

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

  // tau' / stride along this axis for a footprint of std sigma over a level of std sigma_l (0 when
  // the footprint is no wider than the level's plus its tent).
  double spread(double sigma, double sigma_l) const {
    const double t2 = sigma * sigma - sigma_l * sigma_l - 1.0 / (6.0 * inv_stride * inv_stride);
    return t2 > 0.0 ? std::sqrt(t2) * inv_stride : 0.0;
  }

  // The centres around a position (texels) with their weights for a footprint of std sigma over a
  // level of std sigma_l: the Gaussian of std tau' (strides, at most max_spread) integrated against
  // each centre's tent, tau * (F(d + 1/tau) - 2 F(d) + F(d - 1/tau)) with d = (g - i) / tau and
  // F(z) = z Phi(z) + phi(z) (NdfRamp); plain bilinear weights when tau' = 0. Indices wrapped (repeat) or
  // clamped, equal indices merged, weights normalised to sum 1. Writes at most kMaxBlendAxis
  // entries; returns their count.
  int gaussianWeights(double pos, double sigma, double sigma_l, double max_spread, int* idx, double* w) const {
    const double tau = std::fmin(spread(sigma, sigma_l), max_spread);
    if (!(tau > 1e-3)) {
      int i0, i1;
      double f;
      neighbours(pos, &i0, &i1, &f);
      idx[0] = i0;
      w[0] = 1.0 - f;
      if (i1 == i0 || f == 0.0) {
        w[0] = 1.0;
        return 1;
      }
      idx[1] = i1;
      w[1] = f;
      return 2;
    }
    if (repeat) pos -= floorOf(pos * inv_size) * size;
    const double g = (pos - origin) * inv_stride;  // continuous centre index
    const double reach = 3.5 * tau + 1.0;
    if (repeat && 2.0 * reach > 8.0 * n && n <= kWholeGridAxis) {
      // Far wider than a repeating grid: every centre weighs the same (the folded Gaussian is flat
      // to within exp(-2 pi^2 (tau / n)^2) < 1e-9 of its mean).
      for (int i = 0; i < n; ++i) {
        idx[i] = i;
        w[i] = 1.0 / n;
      }
      return n;
    }
    const int first = int(floorOf(g - reach)), last = int(floorOf(g + reach)) + 1;
    int count = 0;
    double total = 0.0;
    const double inv_tau = 1.0 / tau;
    const NdfRamp& ramp = NdfRamp::table();
    // ramp((g - i) / tau) for centres i - 1, i and i + 1: the second difference of neighbouring
    // centres shares two of its three values, so each centre costs one ramp.
    double r_prev = ramp((g - double(first - 1)) * inv_tau), r_cur = ramp((g - double(first)) * inv_tau);
    for (int i = first; i <= last; ++i) {
      const double r_next = ramp((g - double(i + 1)) * inv_tau);
      const double wi = tau * (r_prev - 2.0 * r_cur + r_next);
      r_prev = r_cur;
      r_cur = r_next;
      if (!(wi > 0.0)) continue;
      const int k = repeat ? ((i % n) + n) % n : (i < 0 ? 0 : (i >= n ? n - 1 : i));
      int e = 0;
      while (e < count && idx[e] != k) ++e;
      if (e == count) {
        if (count == kMaxBlendAxis) continue;  // the far tail beyond the entries (below 1e-3)
        idx[count] = k;
        w[count++] = 0.0;
      }
      w[e] += wi;
      total += wi;
    }
    for (int e = 0; e < count; ++e) w[e] /= total;
    return count;
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
  // Spread (tau' in strides) up to which a level answers, and from which the next level is blended
  // in. A level of stride 2 sigma_l samples its footprints' NDF field below its Nyquist rate, and
  // the tau'-Gaussian over its centres only hides the aliasing once q is about 1 or above. With
  // levels of stride 2 sigma_l, sigma_l doubling, the next level's q where it starts to take over
  // (q = 2 here) is 0.83 and where it answers alone (2.5) 1.12. On a 777 x 513 tufted-leather map
  // (relative L1 against the reference): at 96 texels 0.049 when the switch was at 1.0-1.5 (a
  // level at q = 0.37 answered most of it), 0.007 at 1.6-2; at 128 texels 0.019 at 1.6-2 (a level
  // at q = 0.75 had three quarters of it), 0.001 at 2-2.5. The price is more centres per query: up
  // to kMaxBlendAxis per axis.
  static constexpr double kMaxSpread = 2.5;
  static constexpr double kBlendSpread = 2.0;

  // records: `count` level records that passed checkNdfLevelRecord (strides and sigmas finite and
  // positive, sigmas increasing); 1 <= count <= kMaxNdfLevels.
  void init(const NdfLevelRecord* records, int count) {
    count_ = count;
    first_ = 0;
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

  // Calls emit(level, centre, weight) for each of the (at most kMaxBlendCentres) centres a
  // footprint at (x, y) texels of std sigma mixes, centre = j * grid_width + i on its level; the
  // weights sum to 1 (up to the truncation, see above).
  template <typename Emit>
  void blend(double x, double y, double sigma, Emit&& emit) const {
    if (!(sigma > level_[first_].sigma)) {
      blendLevel(first_, 1.0, x, y, emit);
      return;
    }
    int l = first_;
    double q = spread(first_, sigma);
    while (q > kMaxSpread && l + 1 < count_) q = spread(++l, sigma);
    double beta = 0.0;  // weight of level l + 1
    if (q > kBlendSpread && l + 1 < count_) {
      const double t = (q - kBlendSpread) / (kMaxSpread - kBlendSpread);
      beta = t * t * (3.0 - 2.0 * t);
    }
    gaussianLevel(l, 1.0 - beta, x, y, sigma, emit);
    if (beta > 0.0) gaussianLevel(l + 1, beta, x, y, sigma, emit);
  }

  // blend() uses the levels from the first whose sigma is at least `sigma` (the top level when
  // none is): footprints below it get its bilinear blend (NdfSource::answerFromSigma).
  void answerFromSigma(double sigma) {
    first_ = 0;
    while (first_ + 1 < count_ && level_[first_].sigma < sigma) ++first_;
  }
  int firstLevel() const { return first_; }

  // Spread of level l for a footprint of std sigma: the larger of tau' / stride over both axes
  // (0 where the footprint is not wider than the level's own plus its tent).
  double spread(int l, double sigma) const {
    const Level& g = level_[l];
    return std::fmax(g.x.spread(sigma, g.sigma), g.y.spread(sigma, g.sigma));
  }

  // Within level l, the tent-integrated Gaussian weights of the centres around (x, y) for a
  // footprint of std sigma, each times level_weight (weights below 1e-7 skipped), rows then columns.
  template <typename Emit>
  void gaussianLevel(int l, double level_weight, double x, double y, double sigma, Emit& emit) const {
    const Level& g = level_[l];
    int xi[kMaxBlendAxis], yi[kMaxBlendAxis];
    double xw[kMaxBlendAxis], yw[kMaxBlendAxis];
    // The top level of a repeating map spreads as far as the footprint needs when its whole grid
    // fits the weights (a footprint far wider than the map sees the mean of every centre).
    auto reach = [&](const NdfBlendAxis& a) {
      return l == count_ - 1 && a.repeat && a.n <= kWholeGridAxis ? 1e300 : kMaxSpread;
    };
    const int nx = g.x.gaussianWeights(x, sigma, g.sigma, reach(g.x), xi, xw);
    const int ny = g.y.gaussianWeights(y, sigma, g.sigma, reach(g.y), yi, yw);
    for (int b = 0; b < ny; ++b) {
      for (int a = 0; a < nx; ++a) {
        const double w = level_weight * yw[b] * xw[a];
        if (w > 1e-7) emit(l, size_t(yi[b]) * g.grid_width + size_t(xi[a]), w);
      }
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
  int first_ = 0;  // the finest level blend() uses
};

}  // namespace glintbake::format
