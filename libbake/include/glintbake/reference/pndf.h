// SPDX-License-Identifier: Apache-2.0
// The reference P-NDF: the position-normal distribution of a normal map seen through a Gaussian
// pixel footprint, evaluated by summing the closed-form contribution of every flake
// (Yan et al. 2016, section 5; the closed form is written out below).
//
// This is the DEFINITION every fast path is checked against: double precision throughout, a plain
// sum over flakes in a fixed order, no normalisation over the truncated flakes, nothing shared
// with libbake/ndf or runtime/.
//
// Units: footprint centre and std in texels of the source map (formats/SPEC.md coordinates);
// s-plane coordinates s = (n_x, n_y) of a unit normal, tangent frame x = right, y = up;
// densities per unit s-plane area.
#pragma once

#include <glintbake/reference/flakes.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glintbake::reference {

// A Gaussian footprint G_P(u) = N(u; (x, y), sigma^2 I), isotropic, in texels.
struct Footprint {
  double x = 0.0;
  double y = 0.0;
  double sigma = 1.0;  // > 0
};

// Flakes farther than kTruncationSigmas * sqrt(sigma_h^2 + sigma^2) texels from the footprint
// centre are left out of every sum. Their weight is below exp(-18) ~ 1.5e-8 of the peak, and the
// missing mass of a flat map is exp(-18) relative.
constexpr double kTruncationSigmas = 6.0;

// Default intrinsic roughness (std of every flake's normal lobe in the s-plane).
constexpr double kDefaultSigmaR = 0.005;

// Closed form of one flake seen through the footprint:
//   D_k(s) = A_k N(u_k; u_Q, (sigma_h^2 + sigma_p^2) I) N(s; mu_k, C_k)
//   mu_k   = n_k + J_k (sigma_h^2 / (sigma_h^2 + sigma_p^2)) (u_Q - u_k)
//   C_k    = sigma_r^2 I + (sigma_h^2 sigma_p^2 / (sigma_h^2 + sigma_p^2)) J_k J_k^T
struct FlakeLobe {
  double weight;   // A_k N(u_k; u_Q, (sigma_h^2 + sigma_p^2) I): the mass of the lobe (unitless)
  double mean[2];  // mu_k in the s-plane
  double cov[3];   // C_k as {c_xx, c_xy, c_yy}; positive definite (eigenvalues >= sigma_r^2)
};

// The lobe of `flake` placed at position (ux, uy) (its own position, or a periodic image of it
// with wrap=repeat) for footprint `fp` and intrinsic roughness sigma_r. The one place the closed
// form is written. Requires fp.sigma > 0, sigma_r > 0. Thread-safe, pure.
FlakeLobe flakeLobe(const FlakeSet& set, const Flake& flake, double ux, double uy, const Footprint& fp, double sigma_r);

// Density of a lobe at s: weight * N(s; mean, cov). Thread-safe, pure.
double lobeDensity(const FlakeLobe& lobe, double sx, double sy);

// Every lobe of the footprint, in a fixed order (fine row, then fine column, of the unwrapped fine
// grid): each flake within the truncation radius, and with wrap=repeat each periodic image of each
// flake within it (a footprint wider than the map sees several images of a flake). With
// wrap=clamp there are no flakes outside the map.
// Cost: about pi (6 sqrt(sigma_h^2 + sigma^2) rate)^2 lobes of 64 bytes. Thread-safe.
std::vector<FlakeLobe> footprintLobes(const FlakeSet& set, const Footprint& fp, double sigma_r);
// The same into *lobes (cleared first), reusing its capacity: callers that gather one footprint
// after another (a renderer's pixels) allocate once.
void footprintLobes(const FlakeSet& set, const Footprint& fp, double sigma_r, std::vector<FlakeLobe>* lobes);

// Sum of the lobe weights: the integral of D over the whole s-plane (about 1 away from clamped
// edges and for sigma >~ 1 texel; smaller footprints see the flake lattice). Thread-safe.
double footprintWeight(const FlakeSet& set, const Footprint& fp);

// The P-NDF D(s) at one point of the s-plane (any s; not zeroed outside the unit disk): the sum of
// lobeDensity over footprintLobes. Requires fp.sigma > 0, sigma_r > 0 (aborts otherwise).
// Thread-safe; uses one thread.
double evalPndf(const FlakeSet& set, const Footprint& fp, double sx, double sy, double sigma_r);

// Exact integral of weight-free N(s; mean, cov) over the rectangle [x0, x1] x [y0, y1] of the
// s-plane: analytic (erf of the conditional Gaussian) in x, composite 8-point Gauss-Legendre in y
// on panels no wider than one standard deviation of the integrand's y-dependence, over the part
// of [y0, y1] within 9 std of the mean. Relative error below 1e-10 of the lobe's mass.
// Requires x0 <= x1, y0 <= y1. Thread-safe, pure.
double gaussianRectangleIntegral(const double mean[2], const double cov[3], double x0, double x1, double y0, double y1);

// The bin-averaged NDF image of the footprint: res x res bins over s in [-1, 1]^2, row-major, row 0
// at the top (s_y = +1), column 0 at the left (s_x = -1). Each bin holds the EXACT average of D
// over the bin (the sum over lobes of gaussianRectangleIntegral / bin area, lobes in the fixed
// order of footprintLobes); bins whose centre lies outside the unit disk hold 0. Lobe tails
// beyond 9 std are not visited (mass below 1e-18).
// Requires fp.sigma > 0, sigma_r > 0, 1 <= res <= 4096. Parallel over bin rows (TBB, honours the
// caller's task arena); identical bytes for any thread count. Thread-safe.
std::vector<double> binAveragedImage(const FlakeSet& set, const Footprint& fp, double sigma_r, int res);

}  // namespace glintbake::reference
