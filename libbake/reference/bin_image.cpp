// SPDX-License-Identifier: Apache-2.0
// Exact bin averages of the reference P-NDF: the integral of every lobe over every bin it reaches
// (see pndf.h, gaussianRectangleIntegral and binAveragedImage).
//
// A correlated 2D Gaussian factors into the marginal of s_y and the conditional of s_x given s_y,
//   N(s; mu, C) = N(s_y; mu_y, C_yy) N(s_x; mu_x + (C_xy / C_yy)(s_y - mu_y), det(C) / C_yy),
// so its integral over a rectangle is a 1D integral in s_y of an erf difference, which is smooth on
// the scale of min(std_y, conditional std / |C_xy / C_yy|). Composite Gauss-Legendre on panels no
// wider than that scale is exact to ~1e-12 of the lobe's mass.
#include <glintbake/reference/pndf.h>

#include <glintbake/bake/result.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace glintbake::reference {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440084436210485;
constexpr double kInvSqrt2Pi = 0.39894228040143267793994605993438;
// Lobe tails beyond this many standard deviations are not integrated (mass < 1e-18).
constexpr double kTailSigmas = 9.0;

// Gauss-Legendre rules on [-1, 1] (Abramowitz and Stegun, table 25.4): the non-negative half of the
// symmetric nodes, with their weights. On a panel of width w (in units of the integrand's length
// scale) the 4-point rule is exact to ~1e-12 of the panel's mass for w <= 1/4, the 6-point rule to
// ~1e-14 for w <= 1/2 and the 8-point rule to ~1e-15 for w <= 1 (measured on Gaussian times erf
// integrands like ours).
struct GaussLegendreRule {
  int half_count;
  double nodes[4];
  double weights[4];
};
constexpr GaussLegendreRule kGl4 = {2, {0.33998104358485626480, 0.86113631159405257522},
                                    {0.65214515486254614263, 0.34785484513745385737}};
constexpr GaussLegendreRule kGl6 = {3,
                                    {0.23861918608319690863, 0.66120938646626451366, 0.93246951420315202781},
                                    {0.46791393457269104739, 0.36076157304813860757, 0.17132449237917034504}};
constexpr GaussLegendreRule kGl8 = {4,
                                    {0.18343464249564980494, 0.52553240991632898582, 0.79666647741362673959,
                                     0.96028985649753623168},
                                    {0.36268378337836198297, 0.31370664587788728734, 0.22238103445337447054,
                                     0.10122853629037625915}};

// One edge of an interval under the standard normal: the probability of the tail beyond z on the
// side of z's sign, which erfc computes without cancellation.
struct EdgeTail {
  double tail;  // 0.5 erfc(|z| / sqrt 2)
  bool upper;   // z >= 0: the tail is [z, inf); else (-inf, z]
};

EdgeTail edgeTail(double z) {
  return z >= 0.0 ? EdgeTail{0.5 * std::erfc(z * kInvSqrt2), true} : EdgeTail{0.5 * std::erfc(-z * kInvSqrt2), false};
}

// Phi(b) - Phi(a) for edges a <= b, without cancellation in either tail.
double intervalBetween(const EdgeTail& a, const EdgeTail& b) {
  if (a.upper) return a.tail - b.tail;   // both in the upper half
  if (!b.upper) return b.tail - a.tail;  // both in the lower half
  return 1.0 - a.tail - b.tail;          // straddling the mean
}

double normalInterval(double a, double b) { return intervalBetween(edgeTail(a), edgeTail(b)); }

// The factorisation of N(s; mean, cov) along s_y (see the file comment).
struct Conditional {
  double mean_y, std_y;  // marginal of s_y
  double slope;          // d(conditional mean of s_x) / d s_y = C_xy / C_yy
  double std_x;          // conditional std of s_x given s_y: sqrt(det C / C_yy)
  double mean_x;         // conditional mean of s_x at s_y = mean_y
};

Conditional conditionalOf(const double mean[2], const double cov[3]) {
  Conditional c;
  c.mean_x = mean[0];
  c.mean_y = mean[1];
  c.std_y = std::sqrt(cov[2]);
  c.slope = cov[1] / cov[2];
  c.std_x = std::sqrt((cov[0] * cov[2] - cov[1] * cov[1]) / cov[2]);
  return c;
}

// Calls fn(w, m) for the quadrature nodes of the s_y integral over [y0, y1]: w = quadrature weight
// times the s_y marginal density at the node, m = conditional mean of s_x there. Then
//   integral over [x0, x1] x [y0, y1] = sum of w * normalInterval((x0 - m) / std_x, (x1 - m) / std_x).
template <typename Fn>
void forEachYNode(const Conditional& c, double y0, double y1, Fn&& fn) {
  const double lo = std::max(y0, c.mean_y - kTailSigmas * c.std_y);
  const double hi = std::min(y1, c.mean_y + kTailSigmas * c.std_y);
  if (!(lo < hi)) return;
  double scale = c.std_y;
  if (c.slope != 0.0) scale = std::min(scale, c.std_x / std::fabs(c.slope));
  const int panels = std::max(1, int(std::ceil((hi - lo) / scale)));
  const double width = (hi - lo) / double(panels);
  const double relative_width = width / scale;
  const GaussLegendreRule& rule = relative_width <= 0.25 ? kGl4 : (relative_width <= 0.5 ? kGl6 : kGl8);
  const double half = 0.5 * width;
  const double inv_std_y = 1.0 / c.std_y;
  for (int p = 0; p < panels; ++p) {
    const double mid = lo + (double(p) + 0.5) * width;
    for (int k = 0; k < 2 * rule.half_count; ++k) {
      // Nodes in increasing order: the negative half mirrored, then the positive half.
      const int h = k < rule.half_count ? rule.half_count - 1 - k : k - rule.half_count;
      const double node = k < rule.half_count ? -rule.nodes[h] : rule.nodes[h];
      const double y = mid + half * node;
      const double z = (y - c.mean_y) * inv_std_y;
      const double density_y = kInvSqrt2Pi * inv_std_y * std::exp(-0.5 * z * z);
      fn(half * rule.weights[h] * density_y, c.mean_x + c.slope * (y - c.mean_y));
    }
  }
}

// floor(t) clamped to [lo, hi], safe for any finite t.
int binIndexClamped(double t, int lo, int hi) {
  const double f = std::floor(t);
  if (f < double(lo)) return lo;
  if (f > double(hi)) return hi;
  return int(f);
}

}  // namespace

double gaussianRectangleIntegral(const double mean[2], const double cov[3], double x0, double x1, double y0,
                                 double y1) {
  GLINTBAKE_DCHECK(x0 <= x1 && y0 <= y1);
  const Conditional c = conditionalOf(mean, cov);
  const double inv_std_x = 1.0 / c.std_x;
  double total = 0.0;
  forEachYNode(c, y0, y1, [&](double w, double m) {
    total += w * normalInterval((x0 - m) * inv_std_x, (x1 - m) * inv_std_x);
  });
  return total;
}

std::vector<double> binAveragedImage(const FlakeSet& set, const Footprint& fp, double sigma_r, int res) {
  GLINTBAKE_CHECK(fp.sigma > 0.0 && sigma_r > 0.0);
  GLINTBAKE_CHECK(res >= 1 && res <= 4096);
  const std::vector<FlakeLobe> lobes = footprintLobes(set, fp, sigma_r);

  // Per lobe: its factorisation and the s_y extent it is integrated over.
  struct Prepared {
    Conditional c;
    double y_lo, y_hi;
  };
  std::vector<Prepared> prepared(lobes.size());
  for (size_t k = 0; k < lobes.size(); ++k) {
    Prepared& p = prepared[k];
    p.c = conditionalOf(lobes[k].mean, lobes[k].cov);
    p.y_lo = p.c.mean_y - kTailSigmas * p.c.std_y;
    p.y_hi = p.c.mean_y + kTailSigmas * p.c.std_y;
  }

  const double bin = 2.0 / double(res);
  const double inv_bin_area = 1.0 / (bin * bin);
  std::vector<double> image(size_t(res) * size_t(res), 0.0);

  // Rows are independent outputs; within a row the lobes are summed in their fixed order, so the
  // result does not depend on the number of threads.
  tbb::parallel_for(tbb::blocked_range<int>(0, res), [&](const tbb::blocked_range<int>& rows) {
    std::vector<double> acc(static_cast<size_t>(res), 0.0);
    std::vector<EdgeTail> edges(static_cast<size_t>(res) + 1);
    for (int j = rows.begin(); j != rows.end(); ++j) {
      const double y_top = 1.0 - double(j) * bin;  // row 0 is s_y = +1
      const double y_bottom = 1.0 - double(j + 1) * bin;
      const double cy = 1.0 - (double(j) + 0.5) * bin;
      // Columns whose bin centre lies inside the unit disk (a contiguous run, possibly empty).
      int i_lo = res, i_hi = -1;
      for (int i = 0; i < res; ++i) {
        const double cx = -1.0 + (double(i) + 0.5) * bin;
        if (cx * cx + cy * cy <= 1.0) {
          i_lo = std::min(i_lo, i);
          i_hi = std::max(i_hi, i);
        }
      }
      if (i_hi < i_lo) continue;
      std::fill(acc.begin(), acc.end(), 0.0);
      for (size_t k = 0; k < lobes.size(); ++k) {
        const Prepared& p = prepared[k];
        if (p.y_hi < y_bottom || p.y_lo > y_top) continue;
        const double weight = lobes[k].weight;
        const double inv_std_x = 1.0 / p.c.std_x;
        const double reach = kTailSigmas * p.c.std_x;
        forEachYNode(p.c, y_bottom, y_top, [&](double w, double m) {
          // Only the columns within the conditional's tails.
          const int c_lo = binIndexClamped((m - reach + 1.0) / bin, i_lo, i_hi + 1);
          const int c_hi = binIndexClamped((m + reach + 1.0) / bin, i_lo - 1, i_hi);
          if (c_hi < c_lo) return;
          // Tails at the shared edges of the columns, then one interval per column.
          for (int e = c_lo; e <= c_hi + 1; ++e) {
            edges[size_t(e)] = edgeTail((-1.0 + double(e) * bin - m) * inv_std_x);
          }
          const double lobe_w = weight * w;
          for (int i = c_lo; i <= c_hi; ++i) {
            acc[size_t(i)] += lobe_w * intervalBetween(edges[size_t(i)], edges[size_t(i) + 1]);
          }
        });
      }
      double* out = &image[size_t(j) * size_t(res)];
      for (int i = i_lo; i <= i_hi; ++i) out[i] = acc[size_t(i)] * inv_bin_area;
    }
  });
  return image;
}

}  // namespace glintbake::reference
