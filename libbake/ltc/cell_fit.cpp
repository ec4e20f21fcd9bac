// SPDX-License-Identifier: Apache-2.0
// The per-cell LTC fit: the published objective of Heitz et al. 2016 with precomputed sample sets,
// Nelder-Mead, and a Levenberg-Marquardt polish with Ceres.
#include "ltc/cell_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>

namespace glintbake::bake::ltc {

CellMoments computeMoments(BrdfKind brdf, Vec3 v, double alpha, int samples) {
  CellMoments moments;
  Vec3 dir_sum{0, 0, 0};
  for (int j = 0; j < samples; ++j) {
    for (int i = 0; i < samples; ++i) {
      const double u1 = (i + 0.5) / samples;
      const double u2 = (j + 0.5) / samples;
      const Vec3 l = sampleBrdf(brdf, v, alpha, u1, u2);
      double pdf = 0.0;
      const double value = evalBrdf(brdf, v, l, alpha, &pdf);
      if (!(pdf > 0.0)) continue;
      const double weight = value / pdf;
      const Vec3 h = normalize(v + l);
      moments.norm += weight;
      moments.fresnel += weight * std::pow(1.0 - std::max(0.0, dot(v, h)), 5.0);
      dir_sum = dir_sum + weight * l;
    }
  }
  const double n = double(samples) * samples;
  moments.norm /= n;
  moments.fresnel /= n;
  // Isotropic BRDFs have no y component on average; drop the sampling noise.
  dir_sum.y = 0.0;
  moments.average_dir = length(dir_sum) > 0.0 ? normalize(dir_sum) : Vec3{0, 0, 1};
  return moments;
}

CellObjective::CellObjective(BrdfKind brdf, Vec3 v, double alpha, int samples) : brdf_(brdf), v_(v), alpha_(alpha) {
  const size_t n = size_t(samples) * size_t(samples);
  cosine_.reserve(n);
  brdf_dirs_.reserve(n);
  brdf_value_.reserve(n);
  brdf_pdf_.reserve(n);
  for (int j = 0; j < samples; ++j) {
    for (int i = 0; i < samples; ++i) {
      const double u1 = (i + 0.5) / samples;
      const double u2 = (j + 0.5) / samples;
      // Same stratification as the published fitter: u1 drives the cosine, u2 the azimuth.
      const double cos_theta = std::sqrt(u1);
      const double sin_theta = std::sqrt(1.0 - u1);
      const double phi = 2.0 * kPi * u2;
      cosine_.push_back({sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta});
      const Vec3 l = sampleBrdf(brdf, v, alpha, u1, u2);
      double pdf = 0.0;
      const double value = evalBrdf(brdf, v, l, alpha, &pdf);
      brdf_dirs_.push_back(l);
      brdf_value_.push_back(value);
      brdf_pdf_.push_back(pdf);
    }
  }
}

template <typename Sink>
void CellObjective::forEachTerm(const Ltc& ltc, Sink&& sink) const {
  const double inv_n = 1.0 / double(cosine_.size());
  const double scale = ltc.magnitude;
  // LTC samples: L = M w / |M w| has M^-1 L = w / |M w|, so D(L) = (w.z / pi) |det M^-1| |M w|^3.
  for (size_t k = 0; k < cosine_.size(); ++k) {
    const Vec3 w = cosine_[k];
    const Vec3 mw = ltc.m * w;
    const double len = length(mw);
    const Vec3 l = (1.0 / len) * mw;
    const double pdf_ltc = w.z / kPi * ltc.det_inv_m * len * len * len;
    double pdf_brdf = 0.0;
    const double f_brdf = evalBrdf(brdf_, v_, l, alpha_, &pdf_brdf);
    const double diff = std::abs(f_brdf - scale * pdf_ltc);
    const double denom = pdf_ltc + pdf_brdf;
    sink(denom > 0.0 ? diff * diff * diff / denom * inv_n : 0.0);
  }
  // BRDF samples: fixed directions and BRDF values.
  for (size_t k = 0; k < brdf_dirs_.size(); ++k) {
    const double pdf_ltc = ltc.pdf(brdf_dirs_[k]);
    const double diff = std::abs(brdf_value_[k] - scale * pdf_ltc);
    const double denom = pdf_ltc + brdf_pdf_[k];
    sink(denom > 0.0 ? diff * diff * diff / denom * inv_n : 0.0);
  }
}

double CellObjective::operator()(const Ltc& ltc) const {
  double sum = 0.0;
  forEachTerm(ltc, [&sum](double term) { sum += term; });
  return sum;
}

void CellObjective::residuals(const Ltc& ltc, double* out) const {
  size_t k = 0;
  forEachTerm(ltc, [&](double term) { out[k++] = std::sqrt(term); });
}

void applyParams(const double* p, bool isotropic, Ltc* ltc) {
  const double m11 = std::max(p[0], 1e-7);
  const double m22 = std::max(p[1], 1e-7);
  if (isotropic) {
    ltc->m11 = m11;
    ltc->m22 = m11;
    ltc->m13 = 0.0;
  } else {
    ltc->m11 = m11;
    ltc->m22 = m22;
    ltc->m13 = p[2];
  }
  ltc->update();
}

namespace {

using Params = std::array<double, 3>;

// Nelder-Mead with the standard coefficients (reflection 1, expansion 2, inside contraction 1/2,
// shrink 1/2; Nelder and Mead 1965) and the relative stopping test of the published fitter:
// stop when 2 |f_hi - f_lo| < (|f_hi| + |f_lo|) tolerance. Deterministic.
template <typename F>
double nelderMead(F&& f, const Params& start, double delta, double tolerance, int max_iterations, Params* best) {
  constexpr int kDim = 3;
  Params s[kDim + 1];
  double fs[kDim + 1];
  for (int i = 0; i <= kDim; ++i) {
    s[i] = start;
    if (i > 0) s[i][i - 1] += delta;
    fs[i] = f(s[i]);
  }
  auto along = [](const Params& o, const Params& worst, double t) {  // o + t (o - worst)
    Params r;
    for (int d = 0; d < kDim; ++d) r[d] = o[d] + t * (o[d] - worst[d]);
    return r;
  };
  for (int iter = 0; iter < max_iterations; ++iter) {
    int lo = 0, hi = 0, next_hi = 0;
    for (int i = 1; i <= kDim; ++i) {
      if (fs[i] < fs[lo]) lo = i;
      if (fs[i] > fs[hi]) {
        next_hi = hi;
        hi = i;
      } else if (fs[i] > fs[next_hi]) {
        next_hi = i;
      }
    }
    const double a = std::abs(fs[lo]), b = std::abs(fs[hi]);
    if (2.0 * std::abs(a - b) < (a + b) * tolerance) break;

    Params centroid{0, 0, 0};
    for (int i = 0; i <= kDim; ++i)
      if (i != hi)
        for (int d = 0; d < kDim; ++d) centroid[d] += s[i][d] / kDim;

    const Params reflected = along(centroid, s[hi], 1.0);
    const double f_reflected = f(reflected);
    if (f_reflected < fs[next_hi]) {
      if (f_reflected < fs[lo]) {
        const Params expanded = along(centroid, s[hi], 2.0);
        const double f_expanded = f(expanded);
        if (f_expanded < f_reflected) {
          s[hi] = expanded, fs[hi] = f_expanded;
          continue;
        }
      }
      s[hi] = reflected, fs[hi] = f_reflected;
      continue;
    }
    const Params contracted = along(centroid, s[hi], -0.5);
    const double f_contracted = f(contracted);
    if (f_contracted < fs[hi]) {
      s[hi] = contracted, fs[hi] = f_contracted;
      continue;
    }
    for (int i = 0; i <= kDim; ++i) {
      if (i == lo) continue;
      for (int d = 0; d < kDim; ++d) s[i][d] = s[lo][d] + 0.5 * (s[i][d] - s[lo][d]);
      fs[i] = f(s[i]);
    }
  }
  int lo = 0;
  for (int i = 1; i <= kDim; ++i)
    if (fs[i] < fs[lo]) lo = i;
  *best = s[lo];
  return fs[lo];
}

// Ceres residual functor: the square roots of the objective's terms as functions of the parameters.
struct PolishFunctor {
  const CellObjective* objective;
  Ltc base;
  bool isotropic;
  bool operator()(const double* p, double* residuals) const {
    Ltc ltc = base;
    applyParams(p, isotropic, &ltc);
    objective->residuals(ltc, residuals);
    return true;
  }
};

// Levenberg-Marquardt on the square-rooted terms; returns the objective at the result.
double polish(const CellObjective& objective, const Ltc& base, bool isotropic, Params* p) {
  auto* cost = new ceres::NumericDiffCostFunction<PolishFunctor, ceres::FORWARD, ceres::DYNAMIC, 3>(
      new PolishFunctor{&objective, base, isotropic}, ceres::TAKE_OWNERSHIP, objective.residualCount());
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, p->data());
  problem.SetParameterLowerBound(p->data(), 0, 1e-7);
  problem.SetParameterLowerBound(p->data(), 1, 1e-7);
  if (isotropic) problem.SetManifold(p->data(), new ceres::SubsetManifold(3, {1, 2}));
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 6;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.function_tolerance = 1e-9;
  options.parameter_tolerance = 1e-9;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  Ltc ltc = base;
  applyParams(p->data(), isotropic, &ltc);
  return objective(ltc);
}

}  // namespace

double fitCell(const CellObjective& objective, FitMethod method, bool isotropic, Ltc* ltc) {
  const Ltc base = *ltc;
  auto f = [&](const Params& p) {
    Ltc trial = base;
    applyParams(p.data(), isotropic, &trial);
    return objective(trial);
  };
  const Params start{ltc->m11, ltc->m22, ltc->m13};
  // The published fit: Nelder-Mead from the warm start.
  Params best;
  double best_value = nelderMead(f, start, 0.05, 1e-5, 100, &best);
  if (method == FitMethod::kRefined) {
    // Continue from the best point with a fresh, smaller simplex (a restart escapes the collapsed
    // simplex the first run may have stopped with), then polish with Levenberg-Marquardt.
    Params restarted;
    const double restart_value = nelderMead(f, best, 0.01, 1e-7, 100, &restarted);
    if (restart_value < best_value) best = restarted, best_value = restart_value;
    Params p = best;
    const double polished = polish(objective, base, isotropic, &p);
    if (polished < best_value) best = p, best_value = polished;
  }
  applyParams(best.data(), isotropic, ltc);
  return best_value;
}

}  // namespace glintbake::bake::ltc
