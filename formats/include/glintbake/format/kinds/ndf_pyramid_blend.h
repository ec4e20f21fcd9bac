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
//    kMaxSpread (a clamp);
//  - a level of one centre (from the one whose stride reached the map size, on a clamped map)
//    answers up to the next level's sigma, blended with it linearly in log sigma: its image scaled
//    to the footprint's mass over the map (singleLevel), at any width above the top level.
// Repeating maps wrap the centre grid. On a clamped map there is no surface beyond the edges, so a
// centre beyond them (which the grid does not store) has the image of the edge centre scaled by the
// ratio of their footprints' masses over the map (edge falloff, NdfBlendAxis::set): its weight
// goes to the edge centre times that ratio, and a footprint that leaves the map loses the mass the
// reference loses. Every weight is separable (x times y); on a repeating map the weights sum to 1
// up to the truncation at 3.5 tau' (below 1e-3), on a clamped map to less near and beyond the edges.
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
  // Most virtual centres beyond each edge of a clamped axis whose images (scaled edge images) the
  // blend mixes; farther ones weigh below kFoldFloor of the edge centre (or are beyond this count).
  static constexpr int kMaxFold = 32;
  static constexpr double kFoldFloor = 1e-12;

  double size = 1.0, inv_size = 1.0;      // map texels along the axis and their reciprocal
  double origin = 0.0, inv_stride = 1.0;  // centre 0 and 1 / texels between centres
  int n = 1;                              // centres along the axis
  bool repeat = true;
  // Clamped axes: fold[k - 1] is the mass over the map of a level footprint k strides before
  // centre 0 over that of centre 0, and fold_hi the same after centre n - 1 (edge falloff); `folds`
  // of them are above kFoldFloor.
  int folds = 0;
  double fold_lo[kMaxFold] = {}, fold_hi[kMaxFold] = {};
  // Clamped axes whose asset holds the edge centres beyond the edges instead (the tile assets of
  // wang-tiles containers, formats/SPEC.md 10.7): no falloff, and spreads held at max_spread.
  bool hold = false;

  // footprint_std: the level footprint's spatial std along the axis (sigma_l with the flakes' own
  // sigma_h), which sets how fast the mass of centres beyond a clamped edge falls.
  void set(double map_size, double origin_texels, double stride, int centres, bool wraps, double footprint_std) {
    size = map_size;
    inv_size = 1.0 / map_size;
    origin = origin_texels;
    inv_stride = 1.0 / stride;
    n = centres;
    repeat = wraps;
    hold = false;
    folds = 0;
    if (repeat) return;
    const double first = origin, last = origin + double(n - 1) * stride;
    const double m_first = massWithin(first, footprint_std), m_last = massWithin(last, footprint_std);
    if (!(m_first > 0.0) || !(m_last > 0.0)) return;  // degenerate records: hold the edges
    for (int k = 1; k <= kMaxFold; ++k) {
      fold_lo[k - 1] = massWithin(first - k * stride, footprint_std) / m_first;
      fold_hi[k - 1] = massWithin(last + k * stride, footprint_std) / m_last;
      if (!(fold_lo[k - 1] > kFoldFloor) && !(fold_hi[k - 1] > kFoldFloor)) break;
      folds = k;
    }
  }

  // The mass over [0, size] of a normalised Gaussian of std s centred at c (no cancellation on
  // either side of the axis).
  double massWithin(double c, double s) const {
    constexpr double kInvSqrt2 = 0.70710678118654752;
    const double t = c / s * kInvSqrt2, u = (size - c) / s * kInvSqrt2;  // Phi(x) = erfc(-x / sqrt 2) / 2
    if (t <= 0.0) return 0.5 * (std::erfc(-t) - std::erfc(u));
    if (u <= 0.0) return 0.5 * (std::erfc(-u) - std::erfc(t));
    return 1.0 - 0.5 * (std::erfc(t) + std::erfc(u));
  }

  // Centre index i of a clamped axis (any integer) -> the stored centre whose image stands for it
  // and the factor that scales it (1 within the grid, the edge falloff beyond; 0 past the folds).
  int foldedCentre(int i, double* factor) const {
    if (i < 0) {
      *factor = -i <= folds ? fold_lo[-i - 1] : 0.0;
      return 0;
    }
    if (i >= n) {
      *factor = i - n + 1 <= folds ? fold_hi[i - n] : 0.0;
      return n - 1;
    }
    *factor = 1.0;
    return i;
  }

  // The bilinear weights of a position (texels): up to two centres. Repeating axes as neighbours();
  // clamped ones interpolate towards the virtual centres beyond an edge (edge falloff), so both
  // neighbours may be the same edge centre (merged). Returns the count of entries.
  int bilinear(double pos, int* idx, double* w) const {
    const double g = (pos - origin) * inv_stride;              // (unwrapped; only used on clamped axes)
    if (repeat || hold || (g >= 0.0 && g <= double(n - 1))) {  // as neighbours()
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
    // Beyond an edge both neighbours fold onto the edge centre (|g| is bounded by the footprint
    // check, and far beyond the folds both factors are 0).
    const double gc = std::fmax(std::fmin(g, double(n) + kMaxFold + 1.0), -double(kMaxFold) - 2.0);
    const double fl = floorOf(gc), f = gc - fl;
    double a, b;
    idx[0] = foldedCentre(int(fl), &a);
    foldedCentre(int(fl) + 1, &b);
    w[0] = (1.0 - f) * a + f * b;
    return 1;
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

  // An axis of one centre (not held): whatever the spread, its one weight is 1 on a repeating map
  // and the footprint's mass over the map relative to the centre's (the falloff) on a clamped one.
  bool oneCentre() const { return n == 1 && !hold; }

  // tau' / stride along this axis for a footprint of std sigma over a level of std sigma_l (0 when
  // the footprint is no wider than the level's plus its tent).
  double spread(double sigma, double sigma_l) const {
    const double t2 = sigma * sigma - sigma_l * sigma_l - 1.0 / (6.0 * inv_stride * inv_stride);
    return t2 > 0.0 ? std::sqrt(t2) * inv_stride : 0.0;
  }

  // The centres around a position (texels) with their weights for a footprint of std sigma over a
  // level of std sigma_l: the Gaussian of std tau' (strides, at most max_spread) integrated against
  // each centre's tent, tau * (F(d + 1/tau) - 2 F(d) + F(d - 1/tau)) with d = (g - i) / tau and
  // F(z) = z Phi(z) + phi(z) (NdfRamp); bilinear weights when tau' = 0 (bilinear()). Indices
  // wrapped (repeat) or folded onto the edge centres with the edge falloff (clamp), equal indices
  // merged, weights normalised to sum 1 over the window before the falloff. Writes at most
  // kMaxBlendAxis entries; returns their count.
  int gaussianWeights(double pos, double sigma, double sigma_l, double max_spread, int* idx, double* w) const {
    const double tau = std::fmin(spread(sigma, sigma_l), max_spread);
    if (!(tau > 1e-3)) return bilinear(pos, idx, w);
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
    if (!repeat && !hold) return clampedWeights(g, tau, reach, idx, w);
    const int first = int(floorOf(g - reach)), last = int(floorOf(g + reach)) + 1;
    int count = 0;
    double total = 0.0;
    const double inv_tau = 1.0 / tau;
    const NdfRamp& ramp = NdfRamp::table();
    // ramp((g - i) / tau) for centres i - 1, i and i + 1: the second difference of neighbouring
    // centres shares two of its three values, so each centre costs one ramp.
    double r_prev = ramp((g - double(first - 1)) * inv_tau), r_cur = ramp((g - double(first)) * inv_tau);
    // A repeating axis whose window wraps onto at most kMaxBlendAxis centres: centre i lands on
    // entry (i - first) mod n, in the order of the window (no search for its entry).
    const int span = last - first + 1, slots = span < n ? span : n;
    if (repeat && slots <= kMaxBlendAxis) {
      const int k0 = ((first % n) + n) % n;
      for (int e = 0; e < slots; ++e) {
        idx[e] = k0 + e < n ? k0 + e : k0 + e - n;
        w[e] = 0.0;
      }
      int e = 0;
      for (int i = first; i <= last; ++i) {
        const double r_next = ramp((g - double(i + 1)) * inv_tau);
        const double wi = tau * (r_prev - 2.0 * r_cur + r_next);
        r_prev = r_cur;
        r_cur = r_next;
        if (wi > 0.0) {
          w[e] += wi;
          total += wi;
        }
        if (++e == slots) e = 0;
      }
      for (int k = 0; k < slots; ++k) {  // drop the centres that took no weight
        if (w[k] > 0.0) {
          idx[count] = idx[k];
          w[count++] = w[k] / total;
        }
      }
      return count;
    }
    for (int i = first; i <= last; ++i) {
      const double r_next = ramp((g - double(i + 1)) * inv_tau);
      const double wi = tau * (r_prev - 2.0 * r_cur + r_next);
      r_prev = r_cur;
      r_cur = r_next;
      if (!(wi > 0.0)) continue;
      const int k = repeat ? ((i % n) + n) % n : (i < 0 ? 0 : (i >= n ? n - 1 : i));
      if (addWeight(k, wi, idx, w, &count)) total += wi;
    }
    for (int e = 0; e < count; ++e) w[e] /= total;
    return count;
  }

  // gaussianWeights on a clamped axis: the same tent-integrated weights over centres within
  // `reach` strides of g, those beyond the edges folded onto the edge centres with the edge
  // falloff (only the virtual centres with a fold are visited, so any spread costs at most
  // n + 2 kMaxFold steps), normalised by the sum over the whole window (a telescoping sum of the
  // ramp: the footprint keeps the mass it has within the map). Spreads above kDensitySpread use
  // the Gaussian density of variance tau^2 + 1/6 (the tent's) per centre instead, where the
  // ramp's second differences would lose their precision.
  static constexpr double kDensitySpread = 32.0;
  int clampedWeights(double g, double tau, double reach, int* idx, double* w) const {
    const double lo = std::fmax(g - reach, -double(folds) - 1.0),
                 hi = std::fmin(g + reach, double(n - 1 + folds) + 1.0);
    int count = 0;
    if (!(lo <= hi)) return 0;  // the footprint's window misses the map and its folds
    const int first = std::max(int(floorOf(lo)), -folds), last = std::min(int(floorOf(hi)) + 1, n - 1 + folds);
    const bool density = tau > kDensitySpread;
    const double tau_f = std::sqrt(tau * tau + 1.0 / 6.0), inv_tau = 1.0 / (density ? tau_f : tau);
    const NdfRamp& ramp = NdfRamp::table();
    double total;
    if (density) {
      total = std::erf((reach + 0.5) * inv_tau * 0.70710678118654752);
    } else {
      // sum_{i = a..b} tau (r_{i-1} - 2 r_i + r_{i+1}) = tau ((r_{a-1} - r_a) - (r_b - r_{b+1})).
      const double a = floorOf(g - reach), b = floorOf(g + reach) + 1.0;
      total = tau * ((ramp((g - (a - 1.0)) * inv_tau) - ramp((g - a) * inv_tau)) -
                     (ramp((g - b) * inv_tau) - ramp((g - (b + 1.0)) * inv_tau)));
    }
    if (!(total > 0.0)) return 0;
    // The ramp at centres i - 1 and i (the ramp branch; see gaussianWeights).
    double r_prev = density ? 0.0 : ramp((g - double(first - 1)) * inv_tau);
    double r_cur = density ? 0.0 : ramp((g - double(first)) * inv_tau);
    for (int i = first; i <= last; ++i) {
      double wi;
      if (density) {
        const double d = (g - double(i)) * inv_tau;
        wi = 0.39894228040143267794 * inv_tau * std::exp(-0.5 * d * d);
      } else {
        const double r_next = ramp((g - double(i + 1)) * inv_tau);
        wi = tau * (r_prev - 2.0 * r_cur + r_next);
        r_prev = r_cur;
        r_cur = r_next;
      }
      double factor;
      const int k = foldedCentre(i, &factor);
      wi *= factor;
      if (wi > 0.0) addWeight(k, wi, idx, w, &count);
    }
    for (int e = 0; e < count; ++e) w[e] /= total;
    return count;
  }

  // Adds weight wi to centre k's entry (a new one if k has none); false when the entries are full
  // (the far tail beyond them, below 1e-3).
  static bool addWeight(int k, double wi, int* idx, double* w, int* count) {
    int e = 0;
    while (e < *count && idx[e] != k) ++e;
    if (e == *count) {
      if (*count == kMaxBlendAxis) return false;
      idx[*count] = k;
      w[(*count)++] = 0.0;
    }
    w[e] += wi;
    return true;
  }

  // floor() for |x| well inside the int range, without a library call on targets without a
  // rounding instruction; falls back to std::floor outside.
  static double floorOf(double x) {
    if (!(std::fabs(x) < 1e9)) return std::floor(x);
    const double t = double(int64_t(x));
    return t > x ? t - 1.0 : t;
  }
};

// One level of a footprint blend in separable form (NdfPyramidBlend::levels): the centre in
// column xi[a] and row yi[b] of the level's grid weighs what `rule` makes of xw[a] and yw[b], and
// counts when the rule keeps it (forEachInRow and forEachWeight give the kept centres only).
struct NdfBlendLevel {
  // kProduct: level_weight * (xw * yw), kept when xw * yw > 0 (bilinear and one-centre levels);
  // kGaussian: (level_weight * yw) * xw, kept above 1e-7 (the spread's far tail is left out).
  enum Rule { kProduct, kGaussian };
  static constexpr double kGaussianFloor = 1e-7;

  int level = 0;
  size_t grid_width = 1;
  Rule rule = kProduct;
  double level_weight = 1.0;
  int nx = 0, ny = 0;
  int xi[kMaxBlendAxis], yi[kMaxBlendAxis];
  double xw[kMaxBlendAxis], yw[kMaxBlendAxis];

  size_t centre(int a, int b) const { return size_t(yi[b]) * grid_width + size_t(xi[a]); }

  // Calls f(a, weight) for the kept centres of row b, by column.
  template <typename F>
  void forEachInRow(int b, F&& f) const {
    if (rule == kGaussian) {
      const double row = level_weight * yw[b];
      for (int a = 0; a < nx; ++a) {
        const double w = row * xw[a];
        if (w > kGaussianFloor) f(a, w);
      }
      return;
    }
    for (int a = 0; a < nx; ++a) {
      const double w = xw[a] * yw[b];
      if (w > 0.0) f(a, level_weight * w);
    }
  }
  // Calls f(a, b, weight) for the kept centres, rows then columns (emit order of blend()).
  template <typename F>
  void forEachWeight(F&& f) const {
    for (int b = 0; b < ny; ++b) forEachInRow(b, [&](int a, double w) { f(a, b, w); });
  }
  template <typename Emit>
  void forEach(Emit& emit) const {
    forEachWeight([&](int a, int b, double w) { emit(level, centre(a, b), w); });
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
      // A stored footprint's spatial std: sigma_l with the flakes' own sigma_h (formats/SPEC.md 10.5).
      const double step = 1.0 / double(r.rate > 0 ? r.rate : 1), sigma_h = step * 1.5 / std::sqrt(12.0);
      const double footprint_std = std::sqrt(r.sigma_texels * r.sigma_texels + sigma_h * sigma_h);
      g.x.set(double(r.map_width), r.origin_x, r.stride_x, int(r.grid_width), repeat, footprint_std);
      g.y.set(double(r.map_height), r.origin_y, r.stride_y, int(r.grid_height), repeat, footprint_std);
      g.sigma_h2 = sigma_h * sigma_h;
      g.centre_mass =
          repeat ? 1.0 : g.x.massWithin(r.origin_x, footprint_std) * g.y.massWithin(r.origin_y, footprint_std);
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
    NdfBlendLevel parts[2];
    const int n = levels(x, y, sigma, parts);
    for (int p = 0; p < n; ++p) parts[p].forEach(emit);
  }

  // The same blend in separable form: the (one or two) levels it mixes, each with its centres'
  // weights along either axis; parts[p].forEach emits exactly what blend() does, in its order.
  // Queries that only need sum_c w_c f(c) over a grid can walk the axes instead of the centres.
  int levels(double x, double y, double sigma, NdfBlendLevel parts[2]) const {
    if (!(sigma > level_[first_].sigma)) {
      bilinearLevel(first_, 1.0, x, y, &parts[0]);
      return 1;
    }
    int l = first_;
    double q = spread(first_, sigma);
    // A level of one centre has no positions to spread over (its spread only moves mass across a
    // clamped map's edges), so it answers only up to the next level's sigma.
    while (l + 1 < count_ && (singleCentre(l) ? sigma >= level_[l + 1].sigma : q > kMaxSpread)) q = spread(++l, sigma);
    double beta = 0.0;  // weight of level l + 1
    if (l + 1 < count_ && singleCentre(l)) {
      beta = (std::log(sigma) - level_[l].log_sigma) * level_[l].inv_log_step;  // linear in log sigma
      beta = beta > 0.0 ? (beta < 1.0 ? beta : 1.0) : 0.0;
    } else if (q > kBlendSpread && l + 1 < count_) {
      const double t = (q - kBlendSpread) / (kMaxSpread - kBlendSpread);
      beta = t * t * (3.0 - 2.0 * t);
    }
    if (singleCentre(l)) {
      singleLevel(l, 1.0 - beta, x, y, sigma, &parts[0]);
      if (!(beta > 0.0)) return 1;
      singleLevel(l + 1, beta, x, y, sigma, &parts[1]);
      return 2;
    }
    gaussianLevel(l, 1.0 - beta, x, y, sigma, &parts[0]);
    if (!(beta > 0.0)) return 1;
    gaussianLevel(l + 1, beta, x, y, sigma, &parts[1]);
    return 2;
  }

  // A level of one centre for a footprint (x, y, sigma): its image, scaled on a clamped map by the
  // footprint's mass over the map over that of the level's own footprint (no centres to mix: the
  // shape is the level's, the mass the footprint's, exactly, wherever it lies and however wide).
  void singleLevel(int l, double level_weight, double x, double y, double sigma, NdfBlendLevel* out) const {
    const Level& g = level_[l];
    double w = level_weight;
    if (!g.x.repeat) {
      const double s = std::sqrt(sigma * sigma + g.sigma_h2);
      w = g.centre_mass > 0.0 ? w * (g.x.massWithin(x, s) * g.y.massWithin(y, s) / g.centre_mass) : 0.0;
    }
    out->level = l;
    out->grid_width = g.grid_width;
    out->rule = NdfBlendLevel::kProduct;
    out->level_weight = w;
    out->nx = out->ny = w > 0.0 ? 1 : 0;
    out->xi[0] = out->yi[0] = 0;
    out->xw[0] = out->yw[0] = 1.0;
  }

  // blend() uses the levels from the first whose sigma is at least `sigma` (the top level when
  // none is): footprints below it get its bilinear blend (NdfSource::answerFromSigma).
  void answerFromSigma(double sigma) {
    first_ = 0;
    while (first_ + 1 < count_ && level_[first_].sigma < sigma) ++first_;
  }
  int firstLevel() const { return first_; }

  // Spread of level l for a footprint of std sigma: the larger of tau' / stride over both axes
  // (0 where the footprint is not wider than the level's own plus its tent). An axis of one centre
  // (a map narrower than about 1.5 strides: a strip) has no centres to spread over, it is spread
  // to any width (gaussianLevel), so it does not count: otherwise its stride, the map's width,
  // would move a footprint a few times that width to a level far coarser than the other axis needs
  // (a repeating 5 x 700 strip at 40 texels was answered by its level of sigma 64, 0.090 relative
  // L1 against the reference where the smooth baseline is 0.169; from its level of sigma 16, 0.003).
  double spread(int l, double sigma) const {
    const Level& g = level_[l];
    const double qx = g.x.oneCentre() ? 0.0 : g.x.spread(sigma, g.sigma);
    const double qy = g.y.oneCentre() ? 0.0 : g.y.spread(sigma, g.sigma);
    return std::fmax(qx, qy);
  }

  // Within level l, the tent-integrated Gaussian weights of the centres around (x, y) for a
  // footprint of std sigma, each times level_weight (weights below 1e-7 skipped, rows then columns).
  void gaussianLevel(int l, double level_weight, double x, double y, double sigma, NdfBlendLevel* out) const {
    const Level& g = level_[l];
    // The top level spreads as far as the footprint needs when its whole grid fits the weights: on
    // a repeating map a footprint far wider than the map sees the mean of every centre, on a
    // clamped one their Gaussian-weighted sum with the mass the footprint keeps over the map.
    // A level of one centre answers up to the next level's sigma, however far that spreads it.
    // An axis of one centre spreads to any width too: on a clamped map its weight is then the
    // footprint's mass across the map relative to the centre's, as for a level of one centre.
    auto reach = [&](const NdfBlendAxis& a) {
      return unboundedAbove(l, a) || singleCentre(l) || a.oneCentre() ? 1e300 : kMaxSpread;
    };
    out->level = l;
    out->grid_width = g.grid_width;
    out->rule = NdfBlendLevel::kGaussian;
    out->level_weight = level_weight;
    out->nx = g.x.gaussianWeights(x, sigma, g.sigma, reach(g.x), out->xi, out->xw);
    out->ny = g.y.gaussianWeights(y, sigma, g.sigma, reach(g.y), out->yi, out->yw);
  }

  // Within level l, the (up to) 4 nearest centres of (x, y) bilinearly (NdfBlendAxis::bilinear),
  // each weight times level_weight (zero weights skipped), rows then columns.
  void bilinearLevel(int l, double level_weight, double x, double y, NdfBlendLevel* out) const {
    const Level& g = level_[l];
    out->level = l;
    out->grid_width = g.grid_width;
    out->rule = NdfBlendLevel::kProduct;
    out->level_weight = level_weight;
    out->nx = g.x.bilinear(x, out->xi, out->xw);
    out->ny = g.y.bilinear(y, out->yi, out->yw);
  }

  // Whether level l has one centre (and is not held, NdfBlendAxis::hold): a clamped map's top
  // levels from the one whose stride reached the map size.
  bool singleCentre(int l) const {
    const Level& g = level_[l];
    return g.x.n == 1 && g.y.n == 1 && !g.x.hold && !g.y.hold;
  }

  // Whether the blend spreads level l to any width along an axis: the top level's axes of at most
  // kWholeGridAxis centres.
  bool unboundedAbove(int l, const NdfBlendAxis& a) const {
    return l == count_ - 1 && !a.hold && a.n <= kWholeGridAxis;
  }

  // Clamped levels hold their edge centres beyond the edges (NdfBlendAxis::hold): the blend of the
  // tile assets of wang-tiles containers, whose margins already lie beyond their flakes.
  void holdEdges() {
    for (int l = 0; l < count_; ++l) {
      level_[l].x.hold = !level_[l].x.repeat;
      level_[l].y.hold = !level_[l].y.repeat;
    }
  }

 private:
  struct Level {
    NdfBlendAxis x, y;
    size_t grid_width = 1;
    double sigma = 1.0, log_sigma = 0.0;
    double inv_log_step = 0.0;  // 1 / log(sigma_{l+1} / sigma_l); 0 on the top level
    double sigma_h2 = 0.0;      // the flakes' own spatial variance (formats/SPEC.md 10.5)
    double centre_mass = 1.0;   // clamped maps: the mass over the map of centre 0's footprint
  };

  Level level_[kMaxNdfLevels];
  int count_ = 0;
  int first_ = 0;  // the finest level blend() uses
};

}  // namespace glintbake::format
