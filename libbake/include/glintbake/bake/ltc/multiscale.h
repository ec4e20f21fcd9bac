// SPDX-License-Identifier: Apache-2.0
// Multi-scale roughness with LTCs (Tao et al. 2021): the meso-scale roughness of a filtered normal
// map from the length of its averaged normals, and the overall roughness of micro- and meso-scale
// roughness combined. Roughness values here are the isotropic LTC / GGX alpha in [0, 1].
//
// All functions are pure and thread-safe.
#pragma once

#include <glintbake/bake/result.h>

#include <array>
#include <vector>

namespace glintbake::bake::ltc {

// Mean resultant length |b| of the normals of the isotropic LTC with M = diag(alpha, alpha, 1)
// (Tao et al. 2021, eq. 4): |b| = 2 * integral_0^1 mu^2 / sqrt(alpha^2 (1 - mu^2) + mu^2) dmu,
// by Gauss-Legendre quadrature. 1 at alpha = 0, 2/3 at alpha = 1.
double meanResultantLength(double alpha);

// Exact numerical inverse of meanResultantLength on [0, 1]: alpha_me for a given |b|. Lengths at
// or below |b|(1) = 2/3 give 1 (the clamp), lengths >= 1 give 0.
double alphaMesoExact(double length);

// Rational fit of alpha_me(|b|) in y = sqrt(1 - |b|): alpha = y (p0 + p1 y + p2 y^2) /
// (1 + q0 y + q1 y^2), clamped to [0, 1]; 0 at |b| = 1 by construction.
struct MesoFit {
  std::array<double, 5> c{};  // p0, p1, p2, q0, q1
  double eval(double length) const;
};

// Overall alpha of micro roughness a_mi and meso roughness a_me:
// alpha = a_mi + a_me + a_mi a_me (k0 + k1 a_mi + k2 a_me), clamped to [0, 1]. Exact on both axes
// (a_me = 0 gives a_mi; a_mi = 0 gives a_me), as the convolution is.
struct CombineFit {
  std::array<double, 3> k{};
  double eval(double alpha_micro, double alpha_meso) const;
};

// Tao et al. 2021, eq. 7: 0.07 a_mi^2 + 0.94 a_mi + a_me - 0.83 a_mi a_me.
double combinePaper(double alpha_micro, double alpha_meso);

// The overall alpha from the numerical spherical convolution of the two isotropic LTC normal
// distributions: meso normals n ~ LTC(a_me), micro normals m' ~ LTC(a_mi) around n; the histogram
// of the composed normals' cosines is fitted by an isotropic LTC (least squares on the density
// over solid angle, Ceres). Deterministic (stratified samples).
double combineNumerical(double alpha_micro, double alpha_meso);

// Coefficients refitted by fitMultiscale() at its default settings, for bakes that do not refit.
MesoFit defaultMesoFit();
CombineFit defaultCombineFit();

struct FitErrors {
  double rms = 0.0;
  double max = 0.0;
};

struct MultiscaleFit {
  MesoFit meso;
  CombineFit combine;
  FitErrors meso_error;           // of `meso` against alphaMesoExact on the length grid
  FitErrors combine_error;        // of `combine` against combineNumerical on the grid
  FitErrors combine_paper_error;  // of combinePaper against the same ground truth
  int meso_points = 0;
  int combine_grid = 0;  // grid points per axis
};

// Refits both relations with Ceres: meso on `meso_points` lengths evenly spaced in alpha (0, 1],
// combine on a combine_grid x combine_grid grid over (a_mi, a_me) in [0, 1]^2 (computed in parallel,
// deterministic).
Result<MultiscaleFit> fitMultiscale(int meso_points = 256, int combine_grid = 9);

}  // namespace glintbake::bake::ltc
