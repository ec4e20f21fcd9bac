// Integrals of a correlated 2D Gaussian over rectangles and grids of bins (internal to the
// runtime's flake evaluator): analytic in x given y (the conditional is a 1D Gaussian), composite
// 8-point Gauss-Legendre in y on panels no wider than the scale on which the integrand changes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace glintbake::runtime::flakes {

// A 2D Gaussian lobe: mean and covariance {c_xx, c_xy, c_yy}, positive definite.
struct Lobe {
  double mx, my;
  double cxx, cxy, cyy;
};

// Standard normal CDF.
inline double normalCdf(double z) { return 0.5 * std::erfc(-z * 0.70710678118654752440); }

// The lobe's probability over every bin of a grid: column edges xs[0..nc] (increasing) and row
// edges ys[0..nr] (increasing or decreasing: each row is the band between ys[r] and ys[r + 1]),
// accumulated as weight * P into out[r * stride + c]. Bands beyond 8.5 standard deviations of the
// mean are skipped (mass below 2e-17). Integration error below about 1e-10 of the lobe's mass.
template <typename Acc>
void integrateLobeOverGrid(const Lobe& g, double weight, const double* xs, int nc, const double* ys, int nr, Acc* out,
                           int stride) {
  // 8-point Gauss-Legendre nodes and weights on [-1, 1].
  static constexpr double kNode[8] = {-0.96028985649753623, -0.79666647741362674, -0.52553240991632899,
                                      -0.18343464249564980, 0.18343464249564980,  0.52553240991632899,
                                      0.79666647741362674,  0.96028985649753623};
  static constexpr double kWeight[8] = {0.10122853629037626, 0.22238103445337447, 0.31370664587788729,
                                        0.36268378337836198, 0.36268378337836198, 0.31370664587788729,
                                        0.22238103445337447, 0.10122853629037626};
  constexpr double kReach = 8.5;
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
    for (int p = 0; p < panels; ++p) {
      const double mid = a + (p + 0.5) * pw;
      for (int q = 0; q < 8; ++q) {
        const double y = mid + 0.5 * pw * kNode[q];
        const double zy = (y - g.my) / sy;
        const double wy = weight * 0.5 * pw * kWeight[q] * kInvSqrt2Pi / sy * std::exp(-0.5 * zy * zy);
        const double m = g.mx + slope * (y - g.my);
        double prev = normalCdf((xs[0] - m) / sc);
        for (int c = 0; c < nc; ++c) {
          const double cur = normalCdf((xs[c + 1] - m) / sc);
          out[r * stride + c] += Acc(wy * (cur - prev));
          prev = cur;
        }
      }
    }
  }
}

// Probability of the lobe over [x0, x1] x [y0, y1] (x0 <= x1, y0 <= y1).
inline double lobeRectProbability(const Lobe& g, double x0, double x1, double y0, double y1) {
  constexpr double kWhole = 8.5;
  const double sx = std::sqrt(g.cxx), sy = std::sqrt(g.cyy);
  if (g.mx - kWhole * sx >= x0 && g.mx + kWhole * sx <= x1 && g.my - kWhole * sy >= y0 && g.my + kWhole * sy <= y1)
    return 1.0;
  if (g.mx + kWhole * sx <= x0 || g.mx - kWhole * sx >= x1 || g.my + kWhole * sy <= y0 || g.my - kWhole * sy >= y1)
    return 0.0;
  const double xs[2] = {x0, x1}, ys[2] = {y0, y1};
  double p = 0.0;
  integrateLobeOverGrid(g, 1.0, xs, 1, ys, 1, &p, 1);
  return p;
}

// Whether bin (i, j) of an R x R image has its centre inside the unit disk: the others hold 0
// (SPEC.md section 9) and receive nothing.
inline bool binInDisk(int i, int j, int res) {
  const double cx = -1.0 + (i + 0.5) * 2.0 / res, cy = 1.0 - (j + 0.5) * 2.0 / res;
  return cx * cx + cy * cy <= 1.0;
}

// Adds weight * (the lobe's probability over each bin) to the bins of an R x R image (row 0 at
// s_y = +1) whose centre lies inside the unit disk: the bins within 8.5 standard deviations of the
// mean, or the one bin holding the whole lobe.
inline void splatLobe(const Lobe& g, double weight, int res, float* out) {
  const double bin = 2.0 / res, inv_bin = res / 2.0;
  const double rx = 8.5 * std::sqrt(g.cxx), ry = 8.5 * std::sqrt(g.cyy);
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
      integrateLobeOverGrid(g, weight, xs, nc, ys, nr, acc, kSpan);
      for (int r = 0; r < nr; ++r)
        for (int c = 0; c < nc; ++c)
          if (binInDisk(ib + c, jb + r, res)) out[size_t(jb + r) * res + size_t(ib + c)] += float(acc[r * kSpan + c]);
    }
  }
}

}  // namespace glintbake::runtime::flakes
