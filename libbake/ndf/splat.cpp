// SPDX-License-Identifier: Apache-2.0
#include <glintbake/bake/ndf/splat.h>
#include <glintbake/format/numbers.h>

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace glintbake::bake::ndf {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr double kInvSqrt2Pi = 0.39894228040143267794;
constexpr int kMaxSubIntervals = 16;
// Largest drift of a narrow lobe's conditional mean across one sub-interval, in conditional stds.
// The sub-interval's Gaussian stands for that std convolved with a box of the drift's width, whose
// fourth cumulant it leaves out (excess kurtosis -0.007 at 1, -0.075 at 2): images move by 7e-5
// to 3e-4 relative L1 from 1 to 2, and streaks (sharp flakes) splat 20-30% faster (see splat.h).
constexpr double kMaxDrift = 2.0;

// Lobes whose smallest std is at least this many bins are point-evaluated (see splatWideLobe).
constexpr double kWideLobeBins = 1.5;
// Flakes whose spatial exponent |u_k - u_Q|^2 / 2 (sigma_h^2 + sigma_p^2) exceeds kTailExponent
// (weight below e^-3 of the footprint centre's) have their lobes truncated at kTailLobeTruncation
// standard deviations at most (splat.h, "Truncation").
constexpr double kTailExponent = 3.0;
constexpr double kTailLobeTruncation = 3.0;
// Largest spread of a flake's periodic images' lobe means, in units of the lobe's std, at which
// their lobes are splatted as one (Splatter::accumulate, footprints wider than the map). The
// one lobe differs from their sum by the shifts' third cumulant, below kFoldSpread^3 relative.
constexpr double kFoldSpread = 0.1;

// Standard normal CDF and density by linear interpolation of tables (step 1/512 over [-8, 8], built
// once from std::erfc and std::exp at start-up). Interpolation error: h^2/8 max|phi'| = 1.2e-7 for
// the CDF and h^2/8 max|phi''| = 1.9e-7 for the density, far below the splat's 1e-4 budget; each
// entry stores (value, difference to the next) so one lookup touches one cache line. The splat
// evaluates one CDF per bin boundary, so this is its inner loop.
struct NormalTable {
  static constexpr double kMin = -8.0;
  static constexpr double kInvStep = 512.0;
  static constexpr int kCount = 16 * 512 + 1;
  double cdf[kCount][2];
  double pdf[kCount][2];
  NormalTable() {
    for (int i = 0; i < kCount; ++i) {
      const double z = kMin + i / kInvStep;
      cdf[i][0] = 0.5 * std::erfc(-z * kInvSqrt2);
      pdf[i][0] = kInvSqrt2Pi * std::exp(-0.5 * z * z);
    }
    for (int i = 0; i < kCount; ++i) {
      cdf[i][1] = i + 1 < kCount ? cdf[i + 1][0] - cdf[i][0] : 0.0;
      pdf[i][1] = i + 1 < kCount ? pdf[i + 1][0] - pdf[i][0] : 0.0;
    }
  }
};
// Namespace scope (not a function-local static): no initialisation guard in the inner loops.
const NormalTable kNormalTable;

// CDF at table coordinate u = (z - kMin) * kInvStep.
inline double phiCdfTable(double u) {
  if (!(u > 0.0)) return 0.0;
  if (u >= NormalTable::kCount - 1) return 1.0;
  const int i = int(u);
  return kNormalTable.cdf[i][0] + (u - i) * kNormalTable.cdf[i][1];
}

inline double phiCdf(double z) {
  const double u = (z - NormalTable::kMin) * NormalTable::kInvStep;
  if (!(u > 0.0)) return 0.0;
  if (u >= NormalTable::kCount - 1) return 1.0;
  const int i = int(u);
  return kNormalTable.cdf[i][0] + (u - i) * kNormalTable.cdf[i][1];
}

inline double phiPdf(double z) {
  const double u = (z - NormalTable::kMin) * NormalTable::kInvStep;
  if (!(u > 0.0) || u >= NormalTable::kCount - 1) return 0.0;
  const int i = int(u);
  return kNormalTable.pdf[i][0] + (u - i) * kNormalTable.pdf[i][1];
}

// C_k = sigma_r^2 I + kc J_k J_k^T, the lobe covariance of flake k (its record: n_x, n_y, then J
// column-major), for both the per-image and the folded lobes.
inline void lobeCovariance(const float* k, double sr2, double kc, double* cxx, double* cxy, double* cyy) {
  const double j00 = k[2], j10 = k[3], j01 = k[4], j11 = k[5];
  *cxx = sr2 + kc * (j00 * j00 + j01 * j01);
  *cxy = kc * (j00 * j10 + j01 * j11);
  *cyy = sr2 + kc * (j10 * j10 + j11 * j11);
}

}  // namespace

Splatter::Splatter(const FlakeSet& flakes, const SplatParams& params) : flakes_(flakes), params_(params) {
  const int r = params_.ndf_res;
  acc_.assign(size_t(r) * size_t(r), 0.0);
  inside_disk_.resize(size_t(r) * size_t(r));
  const double h = 2.0 / r;
  for (int j = 0; j < r; ++j) {
    for (int i = 0; i < r; ++i) {
      const double sx = -1.0 + (i + 0.5) * h, sy = 1.0 - (j + 0.5) * h;
      inside_disk_[size_t(j) * r + i] = (sx * sx + sy * sy <= 1.0) ? 1 : 0;
    }
  }
}

// A lobe much wider than a bin: the bin average of N(mu, C) equals N(mu, C + h^2/12 I) at the bin
// centre up to the box filter's fourth cumulant, a relative error of about (h / sigma)^4 / 960 *
// He_4, below 2e-4 for sigma >= 1.5 h. The Gaussian is evaluated along each row with the
// two-multiply recurrence of exp(quadratic), so a bin costs about as much as an addition.
static void splatWideLobe(double* acc, int res, double mean_a, double mean_b, double caa, double cab, double cbb,
                          double mass, double truncation) {
  const double h = 2.0 / res;
  caa += h * h / 12.0;
  cbb += h * h / 12.0;
  const double det = caa * cbb - cab * cab;
  const double pa = cbb / det, pab = -cab / det, pb = caa / det;  // precision matrix
  const double bin_mass = mass * h * h / (2.0 * kPi * std::sqrt(det));
  const double sd_b = std::sqrt(cbb);
  const double slope = cab / cbb;                 // E[a | b] = mean_a + slope (b - mean_b)
  const double cond_sd_a = std::sqrt(det / cbb);  // std of a given b
  const int j0 = std::max(0, int(std::floor((mean_b - truncation * sd_b + 1.0) / h)));
  const int j1 = std::min(res - 1, int(std::floor((mean_b + truncation * sd_b + 1.0) / h)));
  const double g = std::exp(-pa * h * h), inv_g = 1.0 / g;
  // r (below) from one row to the next: q's step along a row grows by 2 pab h^2 per row and by
  // 2 pa h^2 per bin that i0 moves, so r takes a factor c_row and one of g (or 1 / g) per bin. The
  // start of the row's first chain (e) still takes an exp: one per row instead of two.
  const double c_row = std::exp(-pab * h * h);
  int i_prev = -1, j_prev = -1;
  double r_prev = 0.0;
  for (int j = j0; j <= j1; ++j) {
    const double db = -1.0 + (j + 0.5) * h - mean_b;
    const double ma = mean_a + slope * db;
    const int i0 = std::max(0, int(std::floor((ma - truncation * cond_sd_a + 1.0) / h)));
    const int i1 = std::min(res - 1, int(std::floor((ma + truncation * cond_sd_a + 1.0) / h)));
    if (i0 > i1) continue;
    const double da = -1.0 + (i0 + 0.5) * h - mean_a;
    const double q = pa * da * da + 2.0 * pab * da * db + pb * db * db;
    double e = bin_mass * std::exp(-0.5 * q);
    // q(i + 1) - q(i) = pa (2 da h + h^2) + 2 pab h db, growing by 2 pa h^2 per step.
    const int di = i0 - i_prev;
    double r;
    if (i_prev >= 0 && j == j_prev + 1 && di >= -2 && di <= 2) {
      r = r_prev * c_row;
      for (int k = 0; k < di; ++k) r *= g;
      for (int k = 0; k > di; --k) r *= inv_g;
    } else {
      r = std::exp(-0.5 * (pa * (2.0 * da * h + h * h) + 2.0 * pab * h * db));
    }
    i_prev = i0;
    j_prev = j;
    r_prev = r;
    // Four interleaved chains (bins i0 + 4m + c, c = 0..3) take the multiply latency off the
    // recurrence and vectorise: over four steps the ratio is r(i) r(i + 1) r(i + 2) r(i + 3) =
    // r(i)^4 g^6, and it grows by g^16 from one step to the next.
    double* row = acc + size_t(j) * size_t(res);
    const double r2 = r * r, g2 = g * g, g4 = g2 * g2, g8 = g4 * g4;
    double ec[4], rc[4];
    ec[0] = e;
    ec[1] = e * r;
    ec[2] = ec[1] * (r * g);
    ec[3] = ec[2] * (r * g2);
    rc[0] = (r2 * r2) * (g4 * g2);
    rc[1] = rc[0] * g4;
    rc[2] = rc[1] * g4;
    rc[3] = rc[2] * g4;
    const double g16 = g8 * g8;
    int i = i0;
#if defined(__SSE2__)
    // Two chains per register: the same IEEE operations lane by lane as the loop below, so the
    // same bits on every x86-64 machine.
    __m128d e01 = _mm_loadu_pd(ec), e23 = _mm_loadu_pd(ec + 2);
    __m128d r01 = _mm_loadu_pd(rc), r23 = _mm_loadu_pd(rc + 2);
    const __m128d step = _mm_set1_pd(g16);
    for (; i + 3 <= i1; i += 4) {
      _mm_storeu_pd(row + i, _mm_add_pd(_mm_loadu_pd(row + i), e01));
      _mm_storeu_pd(row + i + 2, _mm_add_pd(_mm_loadu_pd(row + i + 2), e23));
      e01 = _mm_mul_pd(e01, r01);
      e23 = _mm_mul_pd(e23, r23);
      r01 = _mm_mul_pd(r01, step);
      r23 = _mm_mul_pd(r23, step);
    }
    _mm_storeu_pd(ec, e01);
    _mm_storeu_pd(ec + 2, e23);
#else
    for (; i + 3 <= i1; i += 4) {
      for (int c = 0; c < 4; ++c) {
        row[i + c] += ec[c];
        ec[c] *= rc[c];
        rc[c] *= g16;
      }
    }
#endif
    for (int c = 0; i <= i1; ++i, ++c) row[i] += ec[c];
  }
}

void Splatter::splatLobe(double* acc, int res, double mean_x, double mean_y, double cxx, double cxy, double cyy,
                         double mass, double truncation) {
  {
    // Smallest eigenvalue of the covariance decides between the two integration schemes.
    const double h = 2.0 / res;
    const double half_tr = 0.5 * (cxx + cyy);
    const double disc = std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
    if (half_tr - disc >= (kWideLobeBins * h) * (kWideLobeBins * h)) {
      splatWideLobe(acc, res, mean_x, -mean_y, cxx, -cxy, cyy, mass, truncation);
      return;
    }
  }
  // Work in bin coordinates of both axes: a = s_x (columns), b = -s_y (rows), so bin k of either
  // axis covers [-1 + k h, -1 + (k + 1) h].
  const double h = 2.0 / res;
  double mean_a = mean_x, mean_b = -mean_y, caa = cxx, cab = -cxy, cbb = cyy;
  // Condition on the axis of larger variance: then |slope| <= 1.
  const bool swapped = cbb > caa;
  if (swapped) {
    std::swap(mean_a, mean_b);
    std::swap(caa, cbb);
  }
  const double sd_a = std::sqrt(caa);
  const double slope = cab / caa;
  const double cond_var = std::max(cbb - cab * slope, 1e-30);
  const double cond_sd = std::sqrt(cond_var);
  const size_t stride_a = swapped ? size_t(res) : 1;  // acc step per bin of axis a
  const size_t stride_b = swapped ? 1 : size_t(res);

  const double lo = std::max(mean_a - truncation * sd_a, -1.0);
  const double hi = std::min(mean_a + truncation * sd_a, 1.0);
  if (lo >= hi) return;
  const double inv_h = 0.5 * res;  // lo + 1 and the like are >= 0: truncation is floor below
  const int k0 = std::max(0, int((lo + 1.0) * inv_h));
  const int k1 = std::min(res - 1, int((hi + 1.0) * inv_h));
  const double inv_sd_a = 1.0 / sd_a;
  const double inv_cond_sd = 1.0 / cond_sd;

  // Two passes over chunks of sub-intervals: the first forms each sub-interval's conditional
  // Gaussian (divisions, a square root, table lookups: independent across sub-intervals, so they
  // overlap), the second integrates them over their bins. The additions into acc keep the order
  // of a single pass.
  struct Run {
    double* row;  // first bin
    int count;    // bins
    double scale, u, du;
  };
  constexpr int kChunk = 64;
  Run runs[kChunk];
  int n = 0;
  auto flush = [&]() {
    for (int r = 0; r < n; ++r) {
      const Run& run = runs[r];
      double u = run.u;
      double c_prev = phiCdfTable(u);
      double* row = run.row;
      for (int j = 0; j < run.count; ++j, row += stride_b) {
        u += run.du;
        const double c_next = phiCdfTable(u);
        *row += run.scale * (c_next - c_prev);
        c_prev = c_next;
      }
    }
    n = 0;
  };
  // A column starts where the one before it ended: its first CDF and density are that column's last.
  double end_a = 2.0, end_z = 0.0, end_cdf = 0.0, end_pdf = 0.0;
  for (int k = k0; k <= k1; ++k) {
    const double a0 = std::max(lo, -1.0 + k * h);
    const double a1 = std::min(hi, -1.0 + (k + 1) * h);
    if (a1 <= a0) continue;
    // Sub-intervals keep the conditional mean's drift across each below kMaxDrift conditional stds.
    int subs = int(std::ceil(std::abs(slope) * (a1 - a0) * inv_cond_sd * (1.0 / kMaxDrift)));
    subs = std::clamp(subs, 1, kMaxSubIntervals);
    const double da = (a1 - a0) / subs;
    const bool carried = a0 == end_a;
    double z_prev = carried ? end_z : (a0 - mean_a) * inv_sd_a;
    double cdf_prev = carried ? end_cdf : phiCdf(z_prev), pdf_prev = carried ? end_pdf : phiPdf(z_prev);
    for (int s = 0; s < subs; ++s) {
      const double z_next = ((s + 1 == subs ? a1 : a0 + (s + 1) * da) - mean_a) * inv_sd_a;
      const double cdf_next = phiCdf(z_next), pdf_next = phiPdf(z_next);
      const double w = cdf_next - cdf_prev;
      if (w > 1e-300) {
        // Truncated-normal mean and variance of the primary axis on this sub-interval.
        const double inv_w = 1.0 / w;
        const double ratio = (pdf_prev - pdf_next) * inv_w;
        const double t_mean = mean_a + sd_a * ratio;
        double t_var = caa * (1.0 + (z_prev * pdf_prev - z_next * pdf_next) * inv_w - ratio * ratio);
        t_var = std::max(t_var, 0.0);
        const double m_b = mean_b + slope * (t_mean - mean_a);
        const double sd_b = std::sqrt(cond_var + slope * slope * t_var);
        const double blo = std::max(m_b - truncation * sd_b, -1.0);
        const double bhi = std::min(m_b + truncation * sd_b, 1.0);
        if (blo < bhi) {
          const int j0 = std::max(0, int((blo + 1.0) * inv_h));
          const int j1 = std::min(res - 1, int((bhi + 1.0) * inv_h));
          const double inv_sd_b = 1.0 / sd_b;
          // Table coordinate of the bin boundaries, stepping by h / sd_b per bin.
          runs[n++] = Run{acc + size_t(k) * stride_a + size_t(j0) * stride_b, j1 - j0 + 1, mass * w,
                          ((-1.0 + j0 * h - m_b) * inv_sd_b - NormalTable::kMin) * NormalTable::kInvStep,
                          h * inv_sd_b * NormalTable::kInvStep};
          if (n == kChunk) flush();
        }
      }
      z_prev = z_next;
      cdf_prev = cdf_next;
      pdf_prev = pdf_next;
    }
    end_a = a1;
    end_z = z_prev;
    end_cdf = cdf_prev;
    end_pdf = pdf_prev;
  }
  flush();
}

namespace {

// 1 / R along one axis of `flakes` flakes `step` apart (see footprintPartition); empty when the
// axis is left alone.
std::vector<double> partitionAxis(int flakes, double step, int centres, double stride, double variance) {
  const double sd = std::sqrt(variance);
  if (centres < 2 || !(stride <= kPartitionMaxStride * sd)) return {};
  std::vector<double> inv(size_t(std::max(flakes, 0)));
  const double reach = 10.0 * sd;  // the density below e^-50 beyond
  const double scale = stride / (std::sqrt(2.0 * kPi) * sd);
  for (int g = 0; g < flakes; ++g) {
    const double u = (double(g) + 0.5) * step;
    // Centres (k + 0.5) stride for every integer k: the level's centres and their periodic images
    // (stride * centres is the map's size).
    const int64_t k0 = int64_t(std::floor((u - reach) / stride - 0.5));
    const int64_t k1 = int64_t(std::ceil((u + reach) / stride - 0.5));
    double r = 0.0;
    for (int64_t k = k0; k <= k1; ++k) {
      const double d = u - (double(k) + 0.5) * stride;
      r += std::exp(-0.5 * d * d / variance);
    }
    inv[size_t(g)] = 1.0 / (scale * r);
  }
  return inv;
}

}  // namespace

FootprintPartition footprintPartition(const FlakeSet& flakes, double sigma, int centres_x, double stride_x,
                                      int centres_y, double stride_y) {
  FootprintPartition p;
  if (flakes.wrap != Wrap::kRepeat) return p;
  const double variance = flakes.sigma_h * flakes.sigma_h + sigma * sigma;
  p.x = partitionAxis(flakes.grid_width, flakes.step, centres_x, stride_x, variance);
  p.y = partitionAxis(flakes.grid_height, flakes.step, centres_y, stride_y, variance);
  return p;
}

int64_t Splatter::image(double x, double y, double sigma, float* out, const FootprintPartition* partition) {
  std::fill(acc_.begin(), acc_.end(), 0.0);
  const int64_t used = accumulate(x, y, sigma, 0, 1, acc_.data(), partition);
  finish(acc_.data(), out);
  return used;
}

double Splatter::flakesPerImage(double sigma) const {
  const double r = params_.footprint_truncation * std::sqrt(flakes_.sigma_h * flakes_.sigma_h + sigma * sigma);
  return kPi * r * r / (flakes_.step * flakes_.step);
}

void Splatter::finish(const double* acc, float* out) const {
  const int res = params_.ndf_res;
  const double inv_bin_area = double(res) * double(res) / 4.0;
  const size_t n = size_t(res) * size_t(res);
  for (size_t i = 0; i < n; ++i) out[i] = inside_disk_[i] ? float(acc[i] * inv_bin_area) : 0.0f;
}

int64_t Splatter::accumulate(double x, double y, double sigma, int part, int parts, double* acc,
                             const FootprintPartition* partition) const {
  const int res = params_.ndf_res;
  const FlakeSet& f = flakes_;
  const double sh2 = f.sigma_h * f.sigma_h;
  const double sp2 = sigma * sigma;
  const double s2 = sh2 + sp2;
  const double radius = params_.footprint_truncation * std::sqrt(s2);
  const double radius2 = radius * radius;
  // The footprint weights are scaled by the inverse of the share of the Gaussian inside the
  // truncation disk, so that an image of a footprint inside the map integrates to 1 at any
  // truncation (the flakes beyond stand for the same distribution as those inside).
  const double inside = -std::expm1(-0.5 * params_.footprint_truncation * params_.footprint_truncation);
  const double spatial_norm = f.area / (2.0 * kPi * s2 * inside);
  const double inv_2s2 = 0.5 / s2;
  const double t = sh2 / s2;         // mean shift factor of mu_k
  const double kc = sh2 * sp2 / s2;  // J diag(kc) J^T term of C_k
  const double sr2 = params_.sigma_r * params_.sigma_r;
  const double trunc = params_.lobe_truncation;
  const double tail_trunc = std::min(trunc, kTailLobeTruncation);
  const double tail_d2 = kTailExponent / inv_2s2;

  // Virtual flake indices whose centres may lie within the radius (unwrapped: periodic images of a
  // repeating map are visited as distinct positions).
  const int64_t gx0 = int64_t(std::floor((x - radius) / f.step - 0.5));
  const int64_t gx1 = int64_t(std::ceil((x + radius) / f.step - 0.5));
  const int64_t gy0 = int64_t(std::floor((y - radius) / f.step - 0.5));
  const int64_t gy1 = int64_t(std::ceil((y + radius) / f.step - 0.5));
  const bool repeat = f.wrap == Wrap::kRepeat;
  // Partition factors apply to repeating maps only (footprintPartition leaves clamped ones alone).
  const double* part_x = partition && repeat && !partition->x.empty() ? partition->x.data() : nullptr;
  const double* part_y = partition && repeat && !partition->y.empty() ? partition->y.data() : nullptr;
  // One lobe: the flake k seen from the footprint at offset (dx, dy) = u_k - u_Q, d2 = |.|^2.
  auto lobe = [&](const float* k, double dx, double dy, double d2, double factor) {
    const double j00 = k[2], j10 = k[3], j01 = k[4], j11 = k[5];
    // mu_k = n_k + J_k t (u_Q - u_k), with u_Q - u_k = (-dx, -dy).
    const double mx = k[0] - t * (j00 * dx + j01 * dy);
    const double my = k[1] - t * (j10 * dx + j11 * dy);
    double cxx, cxy, cyy;
    lobeCovariance(k, sr2, kc, &cxx, &cxy, &cyy);
    // Factors of 1 leave the mass's bits as they are.
    const double mass = spatial_norm * std::exp(-d2 * inv_2s2) * factor;
    splatLobe(acc, res, mx, my, cxx, cxy, cyy, mass, d2 > tail_d2 ? tail_trunc : trunc);
  };
  const int64_t width = f.grid_width, height = f.grid_height;
  if (repeat && (2.0 * radius > double(width) * f.step || 2.0 * radius > double(height) * f.step)) {
    // The footprint is wider than the map: it sees each flake at several of its periodic images,
    // whose lobes differ only in mass and in a mean shift t J_k (u_Q - u_k). Their sum is the one
    // lobe of their summed mass whose mean and covariance are the mixture's (the shifts' weighted
    // mean, and C_k plus t^2 J_k V J_k^T, V the weighted covariance of the offsets) up to the
    // shifts' third and higher cumulants. Since C_k >= kc J_k J_k^T, the shifts' spread in C_k's
    // metric is at most t sqrt(|V| / kc), about sigma_h / sigma (0.1 at sigma = 4 sigma_h, 0.002
    // at sigma 256 on rate 1): each flake is folded where that spread is below kFoldSpread, and
    // splatted image by image otherwise. A top level whose footprints span P periods of the map
    // splats each flake once instead of about P^2 times.
    std::vector<int64_t> x_start(size_t(width) + 1), y_start(size_t(height) + 1);
    std::vector<double> x_off, y_off;
    auto offsets = [&](int64_t n, bool along_x, double centre, std::vector<int64_t>& start, std::vector<double>& off) {
      const double period = double(n) * f.step;
      for (int64_t w = 0; w < n; ++w) {
        start[size_t(w)] = int64_t(off.size());
        const double p = (along_x ? f.positionX(w) : f.positionY(w)) - centre;
        const int64_t m0 = int64_t(std::floor((-radius - p) / period)) - 1;
        const int64_t m1 = int64_t(std::ceil((radius - p) / period)) + 1;
        for (int64_t m = m0; m <= m1; ++m) {
          const int64_t g = w + m * n;
          const double d = (along_x ? f.positionX(g) : f.positionY(g)) - centre;
          if (d * d <= radius2) off.push_back(d);
        }
      }
      start[size_t(n)] = int64_t(off.size());
    };
    offsets(width, true, x, x_start, x_off);
    offsets(height, false, y, y_start, y_off);
    struct Image {
      double dx, dy, d2, w;
    };
    std::vector<Image> images;
    int64_t used = 0;
    for (int64_t wy = part; wy < height; wy += parts) {
      const double row_factor = part_y ? part_y[wy] : 1.0;
      for (int64_t wx = 0; wx < width; ++wx) {
        images.clear();
        for (int64_t b = y_start[size_t(wy)]; b < y_start[size_t(wy) + 1]; ++b) {
          const double dy = y_off[size_t(b)], dy2 = dy * dy;
          for (int64_t a = x_start[size_t(wx)]; a < x_start[size_t(wx) + 1]; ++a) {
            const double dx = x_off[size_t(a)], d2 = dx * dx + dy2;
            if (d2 <= radius2) images.push_back(Image{dx, dy, d2, 0.0});
          }
        }
        if (images.empty()) continue;
        const float* k = f.flake(int(wx), int(wy));
        const double factor = row_factor * (part_x ? part_x[wx] : 1.0);
        if (images.size() == 1) {  // as the unfolded loop, bit for bit
          lobe(k, images[0].dx, images[0].dy, images[0].d2, factor);
          ++used;
          continue;
        }
        double sum = 0.0, sx = 0.0, sy = 0.0, d2_min = radius2;
        for (Image& m : images) {
          m.w = std::exp(-m.d2 * inv_2s2);
          sum += m.w;
          sx += m.w * m.dx;
          sy += m.w * m.dy;
          d2_min = std::min(d2_min, m.d2);
        }
        const double mdx = sx / sum, mdy = sy / sum;
        double vxx = 0.0, vxy = 0.0, vyy = 0.0;
        for (const Image& m : images) {
          const double ex = m.dx - mdx, ey = m.dy - mdy;
          vxx += m.w * ex * ex;
          vxy += m.w * ex * ey;
          vyy += m.w * ey * ey;
        }
        vxx /= sum;
        vxy /= sum;
        vyy /= sum;
        const double j00 = k[2], j10 = k[3], j01 = k[4], j11 = k[5];
        double cxx, cxy, cyy;
        lobeCovariance(k, sr2, kc, &cxx, &cxy, &cyy);
        // S = t^2 J V J^T, the covariance of the images' lobe means.
        const double ax = j00 * vxx + j01 * vxy, ay = j00 * vxy + j01 * vyy;  // row 0 of J V
        const double bx = j10 * vxx + j11 * vxy, by = j10 * vxy + j11 * vyy;  // row 1 of J V
        const double t2 = t * t;
        const double sxx = t2 * (ax * j00 + ay * j01), sxy = t2 * (ax * j10 + ay * j11);
        const double syy = t2 * (bx * j10 + by * j11);
        // tr(C^-1 S) bounds the largest eigenvalue of C^-1 S: the spread squared in C's metric.
        const double spread2 = (cyy * sxx - 2.0 * cxy * sxy + cxx * syy) / (cxx * cyy - cxy * cxy);
        if (sum > 0.0 && spread2 <= kFoldSpread * kFoldSpread) {
          const double mx = k[0] - t * (j00 * mdx + j01 * mdy);
          const double my = k[1] - t * (j10 * mdx + j11 * mdy);
          splatLobe(acc, res, mx, my, cxx + sxx, cxy + sxy, cyy + syy, spatial_norm * sum * factor,
                    d2_min > tail_d2 ? tail_trunc : trunc);
          ++used;
          continue;
        }
        for (const Image& m : images) lobe(k, m.dx, m.dy, m.d2, factor);
        used += int64_t(images.size());
      }
    }
    return used;
  }
  int64_t used = 0;
  for (int64_t gy = gy0 + part; gy <= gy1; gy += parts) {
    int64_t wy = gy;
    if (repeat) {
      wy %= height;
      if (wy < 0) wy += height;
    } else if (gy < 0 || gy >= height) {
      continue;
    }
    const double dy = f.positionY(gy) - y;
    const double dy2 = dy * dy;
    if (dy2 > radius2) continue;
    const double row_factor = part_y ? part_y[wy] : 1.0;
    for (int64_t gx = gx0; gx <= gx1; ++gx) {
      const double dx = f.positionX(gx) - x;
      const double d2 = dx * dx + dy2;
      if (d2 > radius2) continue;
      int64_t wx = gx;
      if (repeat) {
        wx %= width;
        if (wx < 0) wx += width;
      } else if (gx < 0 || gx >= width) {
        continue;
      }
      lobe(f.flake(int(wx), int(wy)), dx, dy, d2, row_factor * (part_x ? part_x[wx] : 1.0));
      ++used;
    }
  }
  return used;
}

}  // namespace glintbake::bake::ndf
