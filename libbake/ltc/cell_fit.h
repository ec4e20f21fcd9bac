// SPDX-License-Identifier: Apache-2.0
// Private: the per-cell LTC fit (objective, Nelder-Mead, Ceres polish).
#pragma once

#include <glintbake/bake/ltc/ltc.h>
#include <glintbake/bake/ltc/table.h>

#include <array>
#include <vector>

namespace glintbake::bake::ltc {

// Moments of the BRDF for one cell, estimated from stratified BRDF importance samples.
struct CellMoments {
  double norm = 0.0;
  double fresnel = 0.0;
  Vec3 average_dir{0, 0, 1};
};
CellMoments computeMoments(BrdfKind brdf, Vec3 v, double alpha, int samples);

// The fit objective of one cell with its sample sets precomputed: the BRDF samples and their BRDF
// values are fixed, the LTC samples are the images of fixed cosine samples under M.
class CellObjective {
 public:
  CellObjective(BrdfKind brdf, Vec3 v, double alpha, int samples);
  // Error of `ltc` (published objective; see cellError()).
  double operator()(const Ltc& ltc) const;
  // The individual terms sqrt(|f_brdf - f_ltc|^3 / (pdf_ltc + pdf_brdf) / n): their squares sum to
  // operator(). `out` holds 2 * samples^2 values.
  void residuals(const Ltc& ltc, double* out) const;
  int residualCount() const { return 2 * int(cosine_.size()); }

 private:
  template <typename Sink>
  void forEachTerm(const Ltc& ltc, Sink&& sink) const;

  BrdfKind brdf_;
  Vec3 v_;
  double alpha_;
  std::vector<Vec3> cosine_;        // cosine-distributed unit vectors (LTC sampling, before M)
  std::vector<Vec3> brdf_dirs_;     // BRDF samples L
  std::vector<double> brdf_value_;  // BRDF * cos at those samples
  std::vector<double> brdf_pdf_;
};

// The free parameters of a cell (m11, m22, m13) and how they map onto an Ltc, as the published
// fitter does: m11, m22 clamped to >= 1e-7; isotropic cells use m22 = m11 and m13 = 0.
void applyParams(const double* p, bool isotropic, Ltc* ltc);

// Fits one cell from `ltc`'s current parameters and axes; updates ltc and returns the objective.
double fitCell(const CellObjective& objective, FitMethod method, bool isotropic, Ltc* ltc);

}  // namespace glintbake::bake::ltc
