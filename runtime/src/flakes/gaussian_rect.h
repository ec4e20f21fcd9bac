// SPDX-License-Identifier: Apache-2.0
// Integrals of a correlated 2D Gaussian over rectangles and grids of bins (internal to the
// runtime's flake evaluator): analytic in x given y (the conditional is a 1D Gaussian), composite
// 8-point Gauss-Legendre in y on panels no wider than the scale on which the integrand changes.
#pragma once

#include <glintbake/format/numbers.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace glintbake::runtime::flakes {

// A 2D Gaussian lobe: mean and covariance {c_xx, c_xy, c_yy}, positive definite.
struct Lobe {
  double mx, my;
  double cxx, cxy, cyy;
};

// The point of the lobe for uniforms v1, v2 in [0, 1): Box-Muller, then the Cholesky factor of
// the covariance (how every flake and lobe path samples a lobe it has picked).
inline void lobePoint(const Lobe& g, double v1, double v2, double* x, double* y) {
  const double radius = std::sqrt(-2.0 * std::log1p(-v1));
  const double z0 = radius * std::cos(kTwoPi * v2);
  const double z1 = radius * std::sin(kTwoPi * v2);
  const double l11 = std::sqrt(g.cxx), l21 = g.cxy / l11;
  const double l22 = std::sqrt(std::max(g.cyy - l21 * l21, 0.0));
  *x = g.mx + l11 * z0;
  *y = g.my + l21 * z0 + l22 * z1;
}

// How precisely the integrals are taken. kExact: mass beyond 8.5 standard deviations skipped
// (below 2e-17) and 8-point Gauss-Legendre panels, error below about 1e-10 of the lobe's mass (the
// exact flake path, which is checked against the reference evaluator). kImage: beyond 5.5
// standard deviations skipped (below 4e-8) and 2 or 4 nodes per panel by its width against the
// scale on which the integrand changes, error below about 1e-6 (the clustered lobes, whose own
// approximation is four orders coarser): about ten times cheaper on lobes wider than a bin.
enum class LobeAccuracy { kExact, kImage };

// Standard normal CDF.
inline double normalCdf(double z) { return 0.5 * std::erfc(-z * 0.70710678118654752440); }

// The lobe's probability over every bin of a grid: column edges xs[0..nc] (increasing) and row
// edges ys[0..nr] (increasing or decreasing: each row is the band between ys[r] and ys[r + 1]),
// accumulated as weight * P into out[r * stride + c]. Bands beyond 8.5 standard deviations of the
// mean are skipped (mass below 2e-17). Integration error below about 1e-10 of the lobe's mass.
template <typename Acc>
void integrateLobeOverGrid(const Lobe& g, double weight, const double* xs, int nc, const double* ys, int nr, Acc* out,
                           int stride, LobeAccuracy accuracy = LobeAccuracy::kExact) {
  // 8-point Gauss-Legendre nodes and weights on [-1, 1].
  static constexpr double kNode[8] = {-0.96028985649753623, -0.79666647741362674, -0.52553240991632899,
                                      -0.18343464249564980, 0.18343464249564980,  0.52553240991632899,
                                      0.79666647741362674,  0.96028985649753623};
  static constexpr double kWeight[8] = {0.10122853629037626, 0.22238103445337447, 0.31370664587788729,
                                        0.36268378337836198, 0.36268378337836198, 0.31370664587788729,
                                        0.22238103445337447, 0.10122853629037626};
  // 2- and 4-point rules (kImage): 4 points are within 1e-6 on panels up to 1.5 x the scale, 2
  // points on panels up to 0.16 x.
  static constexpr double kNode2[2] = {-0.57735026918962576, 0.57735026918962576};
  static constexpr double kWeight2[2] = {1.0, 1.0};
  static constexpr double kNode4[4] = {-0.86113631159405258, -0.33998104358485626, 0.33998104358485626,
                                       0.86113631159405258};
  static constexpr double kWeight4[4] = {0.34785484513745386, 0.65214515486254614, 0.65214515486254614,
                                         0.34785484513745386};
  const bool exact = accuracy == LobeAccuracy::kExact;
  const double kReach = exact ? 8.5 : 5.5;
  constexpr double kInvSqrt2Pi = 0.39894228040143267794;
  const double sy = std::sqrt(g.cyy);
  const double slope = g.cxy / g.cyy;
  const double sc = std::sqrt(std::max(g.cxx - g.cxy * slope, 1e-300));
  double h = sy;
  if (std::fabs(slope) * h > sc) h = sc / std::fabs(slope);
  const double ylo = g.my - kReach * sy, yhi = g.my + kReach * sy;
  for (int r = 0; r < nr; ++r) {
    const double a = std::max(std::min(ys[r], ys[r + 1]), ylo);
    const double b = std::min(std::max(ys[r], ys[r + 1]), yhi);
    if (!(b > a)) continue;
    const int panels = std::clamp(int(std::ceil((b - a) / h)), 1, 512);
    const double pw = (b - a) / panels;
    const double* node = kNode;
    const double* node_weight = kWeight;
    int nodes = 8;
    if (!exact) {
      const bool narrow = pw <= 0.16 * h;
      node = narrow ? kNode2 : kNode4;
      node_weight = narrow ? kWeight2 : kWeight4;
      nodes = narrow ? 2 : 4;
    }
    for (int p = 0; p < panels; ++p) {
      const double mid = a + (p + 0.5) * pw;
      for (int q = 0; q < nodes; ++q) {
        const double y = mid + 0.5 * pw * node[q];
        const double zy = (y - g.my) / sy;
        const double wy = weight * 0.5 * pw * node_weight[q] * kInvSqrt2Pi / sy * std::exp(-0.5 * zy * zy);
        const double m = g.mx + slope * (y - g.my);
        // The conditional CDF is 0 below m - kReach sc and 1 above m + kReach sc (to the
        // accuracy's truncation): erfc only at the edges between, nothing added where it is flat.
        const double flat_lo = m - kReach * sc, flat_hi = m + kReach * sc;
        auto cdf = [&](double x) { return x <= flat_lo ? 0.0 : (x >= flat_hi ? 1.0 : normalCdf((x - m) / sc)); };
        double prev = cdf(xs[0]);
        for (int c = 0; c < nc; ++c) {
          const double cur = cdf(xs[c + 1]);
          if (cur != prev) out[r * stride + c] += Acc(wy * (cur - prev));
          prev = cur;
        }
      }
    }
  }
}

// Probability of the lobe over [x0, x1] x [y0, y1] (x0 <= x1, y0 <= y1).
inline double lobeRectProbability(const Lobe& g, double x0, double x1, double y0, double y1,
                                  LobeAccuracy accuracy = LobeAccuracy::kExact) {
  const double kWhole = accuracy == LobeAccuracy::kExact ? 8.5 : 5.5;
  const double sx = std::sqrt(g.cxx), sy = std::sqrt(g.cyy);
  if (g.mx - kWhole * sx >= x0 && g.mx + kWhole * sx <= x1 && g.my - kWhole * sy >= y0 && g.my + kWhole * sy <= y1)
    return 1.0;
  if (g.mx + kWhole * sx <= x0 || g.mx - kWhole * sx >= x1 || g.my + kWhole * sy <= y0 || g.my - kWhole * sy >= y1)
    return 0.0;
  const double xs[2] = {x0, x1}, ys[2] = {y0, y1};
  double p = 0.0;
  integrateLobeOverGrid(g, 1.0, xs, 1, ys, 1, &p, 1, accuracy);
  return p;
}

// Whether bin (i, j) of an R x R image has its centre inside the unit disk: the others hold 0
// (SPEC.md section 9) and receive nothing.
inline bool binInDisk(int i, int j, int res) {
  const double cx = -1.0 + (i + 0.5) * 2.0 / res, cy = 1.0 - (j + 0.5) * 2.0 / res;
  return cx * cx + cy * cy <= 1.0;
}

// Adds weight * (the lobe's probability over each bin) to the bins of an R x R image (row 0 at
// s_y = +1) whose centre lies inside the unit disk: the bins within the reach of the accuracy
// (8.5 or 5.5 standard deviations of the mean), or the one bin holding the whole lobe.
inline void splatLobe(const Lobe& g, double weight, int res, float* out, LobeAccuracy accuracy = LobeAccuracy::kExact) {
  const double bin = 2.0 / res, inv_bin = res / 2.0;
  const double reach = accuracy == LobeAccuracy::kExact ? 8.5 : 5.5;
  const double rx = reach * std::sqrt(g.cxx), ry = reach * std::sqrt(g.cyy);
  const int i0 = std::max(0, int(std::floor((g.mx - rx + 1.0) * inv_bin)));
  const int i1 = std::min(res - 1, int(std::floor((g.mx + rx + 1.0) * inv_bin)));
  const int j0 = std::max(0, int(std::floor((1.0 - (g.my + ry)) * inv_bin)));
  const int j1 = std::min(res - 1, int(std::floor((1.0 - (g.my - ry)) * inv_bin)));
  if (i0 > i1 || j0 > j1) return;
  if (i0 == i1 && j0 == j1 && g.mx - rx >= -1.0 + i0 * bin && g.mx + rx <= -1.0 + (i0 + 1) * bin &&
      g.my + ry <= 1.0 - j0 * bin && g.my - ry >= 1.0 - (j0 + 1) * bin) {
    if (binInDisk(i0, j0, res)) out[size_t(j0) * res + i0] += float(weight);
    return;
  }
  constexpr int kSpan = 32;  // bins per side integrated at once
  double xs[kSpan + 1], ys[kSpan + 1], acc[kSpan * kSpan];
  for (int jb = j0; jb <= j1; jb += kSpan) {
    const int nr = std::min(kSpan, j1 - jb + 1);
    for (int ib = i0; ib <= i1; ib += kSpan) {
      const int nc = std::min(kSpan, i1 - ib + 1);
      for (int c = 0; c <= nc; ++c) xs[c] = -1.0 + (ib + c) * bin;
      for (int r = 0; r <= nr; ++r) ys[r] = 1.0 - (jb + r) * bin;
      std::fill(acc, acc + nr * kSpan, 0.0);
      integrateLobeOverGrid(g, weight, xs, nc, ys, nr, acc, kSpan, accuracy);
      for (int r = 0; r < nr; ++r)
        for (int c = 0; c < nc; ++c)
          if (binInDisk(ib + c, jb + r, res)) out[size_t(jb + r) * res + size_t(ib + c)] += float(acc[r * kSpan + c]);
    }
  }
}

}  // namespace glintbake::runtime::flakes
