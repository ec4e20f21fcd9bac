// SPDX-License-Identifier: Apache-2.0
// Sweep kernels of CP-ALS and HALS with a dimension tree (Kolda & Bader 2009, sec. 3.4; Phan et
// al. 2013, "Fast alternating LS algorithms for high order CANDECOMP/PARAFAC tensor
// factorizations"): the two large contractions are single-threaded Eigen GEMMs, everything else is
// O(B^2 R + K R^2).
#include "cp_engine.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

namespace glintbake::bake::tensor {

namespace {
// Relative squared error below which errorSquared() forms the residual explicitly.
constexpr double kGramErrorFloor = 1e-5;
}  // namespace

MatD gram(const MatF& m) {
  const MatD md = m.cast<double>();
  MatD g(md.cols(), md.cols());
  g.noalias() = md.transpose() * md;
  return g;
}

namespace {

// Column r of m to unit norm, its norm into absorb's column r. The float arithmetic below is the
// packer's historical one and is kept bit for bit whenever its results are finite. A rank-1 term
// that is dying (its scale, carried by C, decaying through the float subnormals) or being revived
// from such a column has norms whose reciprocal or product leaves the float range (1 / 1e-40, a
// HALS column of 1e43 computed in double); those columns are scaled in double from `exact` (the
// column before its float rounding) or from m itself, so no inf or NaN can appear. Returns the
// norm (1 for a zero column); *widened is set when the double path ran.
double normaliseColumn(MatF& m, Eigen::Index r, MatF* absorb, const Eigen::VectorXd* exact, bool* widened) {
  const double norm = m.col(r).cast<double>().norm();
  if (!(norm > 0.0)) return 1.0;  // a zero column stays zero (its term is dead)
  if (std::isfinite(norm)) {
    const float inverse = static_cast<float>(1.0 / norm), scale = static_cast<float>(norm);
    const Eigen::VectorXf unit = m.col(r) * inverse;
    bool finite = unit.allFinite();
    Eigen::VectorXf absorbed;
    if (finite && absorb) {
      absorbed = absorb->col(r) * scale;
      finite = absorbed.allFinite();
    }
    if (finite) {
      m.col(r) = unit;
      if (absorb) absorb->col(r) = absorbed;
      return norm;
    }
  }
  const Eigen::VectorXd wide = exact ? *exact : Eigen::VectorXd(m.col(r).cast<double>());
  const double wide_norm = wide.norm();
  if (!(wide_norm > 0.0) || !std::isfinite(wide_norm)) return 1.0;
  m.col(r) = (wide / wide_norm).cast<float>();
  if (absorb) absorb->col(r) = (absorb->col(r).cast<double>() * wide_norm).cast<float>();
  if (widened) *widened = true;
  return wide_norm;
}

}  // namespace

Eigen::VectorXd normaliseColumns(MatF& m, MatF* absorb, const MatD* exact, bool* widened) {
  Eigen::VectorXd norms = Eigen::VectorXd::Ones(m.cols());
  for (Eigen::Index r = 0; r < m.cols(); ++r) {
    if (exact) {
      const Eigen::VectorXd column = exact->col(r);
      norms[r] = normaliseColumn(m, r, absorb, &column, widened);
    } else {
      norms[r] = normaliseColumn(m, r, absorb, nullptr, widened);
    }
  }
  return norms;
}

MatD solveNormalEquations(const MatD& m, const MatD& g, double ridge) {
  const Eigen::Index rank = g.rows();
  const double scale = std::max(g.trace() / static_cast<double>(rank), 1e-300);
  MatD regularised = g;
  regularised.diagonal().array() += ridge * scale;
  Eigen::LLT<MatD> llt(regularised);
  if (llt.info() == Eigen::Success) return llt.solve(m.transpose()).transpose();
  // Rank-deficient Gram (e.g. an all-zero column with ridge 0): fall back to a pivoted LDL^T
  // with a slightly larger ridge.
  regularised.diagonal().array() += 1e-12 * scale;
  return regularised.ldlt().solve(m.transpose()).transpose();
}

CpEngine::CpEngine(const float* x, int bins, int blocks, int rank)
    : xt_(x, static_cast<Eigen::Index>(bins) * bins, blocks),
      bins_(bins),
      blocks_(blocks),
      rank_(rank),
      c_rows_(blocks) {
  double sum = 0.0;
  const size_t count = static_cast<size_t>(bins) * bins * blocks;
  for (size_t n = 0; n < count; ++n) sum += static_cast<double>(x[n]) * x[n];
  norm_sq_ = sum;
  const Eigen::Index n = static_cast<Eigen::Index>(bins) * bins;
  w_.resize(n, rank);
  kr_.resize(n, rank);
  mc_.resize(blocks, rank);
  m_.resize(bins, rank);
}

CpEngine::CpEngine(const float* core, int bins, int basis, int rank, const MatF* q)
    : CpEngine(core, bins, basis, rank) {
  expand_ = q;
  c_rows_ = static_cast<int>(q->rows());
  mc_.resize(c_rows_, rank);
}

void CpEngine::contractW(const MatF& c) {
  if (expand_) {
    const MatF cq = expand_->transpose() * c;  // L x R
    w_.noalias() = xt_ * cq;
  } else {
    w_.noalias() = xt_ * c;
  }
}

// GCC 12 reports -Wuse-after-free inside Eigen's aligned_free when it inlines the resize of `tmp`
// (already of the right size, so never reallocated) into this loop: a known false positive of
// GCC 12's new warning. Silenced for this one function only.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuse-after-free"
#endif
void CpEngine::contractModeA(const MatF& b, MatD& out) const {
  out.resize(bins_, rank_);
  Eigen::VectorXf tmp(bins_);
  for (int r = 0; r < rank_; ++r) {
    Eigen::Map<const MatF> wr(w_.col(r).data(), bins_, bins_);  // W_r(i, j)
    tmp.noalias() = wr * b.col(r);
    out.col(r) = tmp.cast<double>();
  }
}
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic pop
#endif

void CpEngine::contractModeB(const MatF& a, MatD& out) const {
  out.resize(bins_, rank_);
  Eigen::VectorXf tmp(bins_);
  for (int r = 0; r < rank_; ++r) {
    Eigen::Map<const MatF> wr(w_.col(r).data(), bins_, bins_);
    tmp.noalias() = wr.transpose() * a.col(r);
    out.col(r) = tmp.cast<double>();
  }
}

void CpEngine::contractModeC(const MatF& a, const MatF& b) {
  for (int r = 0; r < rank_; ++r) {
    for (int j = 0; j < bins_; ++j)
      kr_.col(r).segment(static_cast<Eigen::Index>(j) * bins_, bins_) = a.col(r) * b(j, r);
  }
  if (expand_) {
    const MatF core_mc = xt_.transpose() * kr_;  // L x R
    mc_.noalias() = *expand_ * core_mc;
  } else {
    mc_.noalias() = xt_.transpose() * kr_;
  }
}

double CpEngine::errorSquared(const MatD& ata, const MatD& btb, const MatF& c) const {
  const MatD ctc = gram(c);
  double inner = 0.0;
  for (int r = 0; r < rank_; ++r) {
    for (int k = 0; k < c_rows_; ++k) inner += static_cast<double>(mc_(k, r)) * c(k, r);
  }
  const double model = (ata.array() * btb.array() * ctc.array()).sum();
  const double err_sq = norm_sq_ - 2.0 * inner + model;
  if (err_sq > kGramErrorFloor * norm_sq_ || expand_) return std::max(err_sq, 0.0);
  // Near-exact fits: the Gram identity cancels |X|^2 against float-rounded inner products (noise
  // about 1e-7 |X|^2), so the residual is formed explicitly instead; kr_ holds B kr A.
  MatF model_t(xt_.rows(), blocks_);
  model_t.noalias() = kr_ * c.transpose();
  double sum = 0.0;
  for (Eigen::Index k = 0; k < blocks_; ++k) {
    for (Eigen::Index n = 0; n < xt_.rows(); ++n) {
      const double d = static_cast<double>(xt_(n, k)) - model_t(n, k);
      sum += d * d;
    }
  }
  return sum;
}

double CpEngine::alsSweep(CpState& s, double ridge) {
  contractW(s.c);
  const MatD ctc = gram(s.c);

  contractModeA(s.b, m_);
  MatD g = gram(s.b).cwiseProduct(ctc);
  s.a = solveNormalEquations(m_, g, ridge).cast<float>();
  normaliseColumns(s.a, nullptr);

  contractModeB(s.a, m_);
  const MatD ata = gram(s.a);
  g = ata.cwiseProduct(ctc);
  s.b = solveNormalEquations(m_, g, ridge).cast<float>();
  normaliseColumns(s.b, nullptr);

  return solveC(s, ridge, false);
}

namespace {

// One pass of HALS column updates on F (rows x R) for the problem min |M - F G|, F >= 0:
// f_r <- max(0, f_r + (m_r - F g_r) / g_rr), columns in order (Cichocki & Phan 2009). A column
// that reaches zero stays zero (the model loses that rank-1 term). The update runs in double;
// `exact` (when given) receives it before the rounding to float, for normaliseColumns: the update
// of A or B against a dying term's subnormal C column (g_rr ~ |c_r|^2 ~ 1e-86) is of the order
// 1 / |c_r| and overflows float, though its product with c_r is an ordinary rank-1 term.
void halsUpdate(MatF& f, const MatD& m, const MatD& g, MatD* exact = nullptr) {
  MatD fd = f.cast<double>();
  for (Eigen::Index r = 0; r < fd.cols(); ++r) {
    const double diag = g(r, r);
    if (!(diag > 0.0)) continue;
    Eigen::VectorXd col = fd.col(r) + (m.col(r) - fd * g.col(r)) / diag;
    fd.col(r) = col.cwiseMax(0.0);
  }
  f = fd.cast<float>();
  if (exact) *exact = std::move(fd);
}

}  // namespace

double CpEngine::halsSweep(CpState& s) {
  contractW(s.c);
  MatD ctc = gram(s.c);

  MatD exact;
  bool widened = false;
  contractModeA(s.b, m_);
  halsUpdate(s.a, m_, gram(s.b).cwiseProduct(ctc), &exact);
  const Eigen::VectorXd norms = normaliseColumns(s.a, &s.c, &exact, &widened);
  if (widened) {
    // A norm beyond the float range moved into C (a revived term): contract again rather than
    // scale W by a factor float cannot hold.
    contractW(s.c);
    ctc = gram(s.c);
  } else {
    // W = X^T C is linear in C: absorbing A's norms into C scales W's columns the same way.
    // C^T C follows the same scaling: (D C^T C D)(i, j) = n_i n_j (C^T C)(i, j).
    for (int r = 0; r < rank_; ++r) w_.col(r) *= static_cast<float>(norms[r]);
    ctc = norms.asDiagonal() * ctc * norms.asDiagonal();
  }

  contractModeB(s.a, m_);
  halsUpdate(s.b, m_, gram(s.a).cwiseProduct(ctc), &exact);
  normaliseColumns(s.b, &s.c, &exact, nullptr);

  return solveC(s, 0.0, true);
}

double CpEngine::evaluate(const CpState& s) {
  contractModeC(s.a, s.b);
  return errorSquared(gram(s.a), gram(s.b), s.c);
}

double CpEngine::solveC(CpState& s, double ridge, bool nonneg) {
  contractModeC(s.a, s.b);
  const MatD ata = gram(s.a);
  const MatD btb = gram(s.b);
  const MatD g = ata.cwiseProduct(btb);
  if (nonneg) {
    halsUpdate(s.c, mc_.cast<double>(), g);
  } else {
    s.c = solveNormalEquations(mc_.cast<double>(), g, ridge).cast<float>();
  }
  return errorSquared(ata, btb, s.c);
}

}  // namespace glintbake::bake::tensor
