// SPDX-License-Identifier: Apache-2.0
// The sweep kernels of CP-ALS and HALS over one B x B x K tensor stored K x (B*B) row-major
// (private to libbake/tensor). See cp_decomposition.h for the method.
#pragma once

#include <Eigen/Core>

#include <cstdint>

namespace glintbake::bake::tensor {

using MatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;  // column-major
using MatD = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic>;

// Factor matrices, column-major: a (B x R), b (B x R), c (K x R). After a sweep, a and b have
// unit-norm columns and c carries the scales.
struct CpState {
  MatF a, b, c;
};

class CpEngine {
 public:
  // x: K x (B*B) row-major values (read as the column-major (B*B) x K matrix X^T); must outlive
  // the engine.
  CpEngine(const float* x, int bins, int blocks, int rank);
  // Compressed engine: x holds the B x B x L core of a tensor compressed in mode 3 by an
  // orthonormal basis q (K x L), i.e. the data are X~ = core x_3 q, while C stays K x R. Sweeps then
  // cost O(B^2 L R + K L R) instead of O(B^2 K R), and their errors are measured against X~ (|X~| =
  // |core|). Used to run non-negative sweeps (whose constraint lives on the full C) on compressed
  // data. q must outlive the engine.
  CpEngine(const float* core, int bins, int basis, int rank, const MatF* q);

  int bins() const { return bins_; }
  int blocks() const { return c_rows_; }
  int rank() const { return rank_; }
  double normSquared() const { return norm_sq_; }
  const float* data() const { return xt_.data(); }

  // One least-squares sweep (W = C^T X, A, B, then C from X (B kr A)); reads s.b and s.c, writes
  // all three. Returns the squared error of the new model.
  double alsSweep(CpState& s, double ridge);

  // One non-negative HALS sweep, same contractions, in-place projected column updates.
  double halsSweep(CpState& s);

  // Squared error of a given model (one mode-3 contraction).
  double evaluate(const CpState& s);

  // C from A and B only (least squares, or HALS when nonneg); returns the squared error.
  double solveC(CpState& s, double ridge, bool nonneg);

 private:
  void contractW(const MatF& c);                       // w_ = X^T C
  void contractModeA(const MatF& b, MatD& out) const;  // out(i, r) = sum_j W_r(i, j) b(j, r)
  void contractModeB(const MatF& a, MatD& out) const;  // out(j, r) = sum_i W_r(i, j) a(i, r)
  void contractModeC(const MatF& a, const MatF& b);    // mc_ = X (B kr A)
  // Squared error of the model (A, B, c); requires contractModeC(A, B) to have run.
  double errorSquared(const MatD& ata, const MatD& btb, const MatF& c) const;

  Eigen::Map<const MatF> xt_;  // (B*B) x K
  int bins_, blocks_, rank_;
  int c_rows_;                    // rows of C: blocks_, or K of a compressed engine
  const MatF* expand_ = nullptr;  // compressed engine: the K x L basis
  double norm_sq_ = 0.0;
  MatF w_;   // (B*B) x R
  MatF kr_;  // (B*B) x R
  MatF mc_;  // K x R (rows of C)
  MatD m_;   // B x R scratch
};

// Column-wise helpers shared by the drivers.
MatD gram(const MatF& m);  // m^T m in double
// Scales m's columns to unit norm (zero columns stay zero) and multiplies absorb's columns by the
// norms (when given). Returns the norms (1 for zero columns). Norms outside the float range (a
// subnormal column, or a HALS column that overflowed float) are applied in double, from `exact`
// (m before its rounding to float, same size) when given, and set *widened (so a term revived from
// a subnormal C column keeps finite factors, its scale in C).
Eigen::VectorXd normaliseColumns(MatF& m, MatF* absorb, const MatD* exact = nullptr, bool* widened = nullptr);
// Solves X * G = M for X (G symmetric positive semi-definite, R x R) with a relative ridge.
MatD solveNormalEquations(const MatD& m, const MatD& g, double ridge);

}  // namespace glintbake::bake::tensor
