// SPDX-License-Identifier: Apache-2.0
// Fast P-NDF images of Gaussian footprints by splatting flakes into bins (Yan et al. 2016, the
// per-element closed form of glintbake/reference/pndf.h).
//
// For a footprint N(u; u_Q, sigma_p^2 I) every flake k within the truncation radius contributes
//   D_k(s) = A_k N(u_k; u_Q, (sigma_h^2 + sigma_p^2) I) N(s; mu_k, C_k)
// whose s-lobe is integrated over the bins it touches (not point-sampled: the default
// sigma_r = 0.005 is a third of a 128-bin). Lobes whose smallest std is at least 1.5 bins are wide:
// the bin's box filter is folded into the covariance (C + h^2/12 I, exact up to the box's fourth
// cumulant, < 2e-4 relative) and the Gaussian is evaluated at bin centres with an incremental
// exp recurrence. Narrower lobes are integrated with erf: the lobe is conditioned on its axis of
// larger variance; that axis is integrated with erf per bin, split into a few sub-intervals when the
// lobe is correlated; on each sub-interval the other axis is a Gaussian (conditional mean at the
// sub-interval's truncated-normal mean, variance plus the slope's share of its truncated variance)
// integrated with erf per bin. Uncorrelated lobes (flat regions) are integrated exactly; the
// sub-interval count bounds the drift of the conditional mean across a sub-interval to two
// conditional stds (a bound of one std moves the images by 7e-5 to 3e-4 relative L1 and takes
// 20-30% longer on sharp flakes, whose lobes are streaks).
//
// Truncation (documented defaults):
//  - footprint: flakes farther than footprint_truncation * sqrt(sigma_h^2 + sigma_p^2) from u_Q are
//    skipped, and the weights of the others are divided by the share of the footprint inside that
//    disk, 1 - exp(-T^2 / 2), so that images keep unit mass. At the default 3.5 std the flakes left
//    out hold exp(-6.125) = 2.2e-3 of the weight, and images are within 6e-4 to 3.8e-3 relative L1
//    of the exact bin averages (glintbake/reference; Beckmann and flake maps of 256^2, sigma 4-32).
//    At 4 std they are within 2.5e-4 to 8.3e-4, for (4 / 3.5)^2 = 1.31 times the lobes and 20-25%
//    more time (the bakers' --footprint-truncation);
//  - lobe: each lobe is integrated over +-4 std of both conditional axes (missing mass < 1.3e-4),
//    the lobes of flakes in the footprint's tail (weight below e^-3 of the centre's, 4.8% of the
//    footprint's mass and 51% of its flakes at 3.5 std) over +-3 std (missing mass < 5.4e-3 of
//    theirs, so < 2.6e-4 of the image's). That saved 16% of an image's time (bench_ndf, sigma 2-32)
//    and 38% of a 1024^2 curved-scratches bake, whose wide lobes cover the most bins.
//
// Image layout (formats/SPEC.md): R x R bins over s in [-1,1]^2, row 0 at s_y = +1, column 0 at
// s_x = -1; each bin stores its average density (mass / bin area); bins whose centre lies outside
// the unit disk hold 0. Wrap::kRepeat maps contribute every periodic image of every flake within the
// radius; Wrap::kClamp maps have no flakes outside the map.
//
// Footprints wider than a repeating map (the top levels) see each flake at several periodic
// images, whose lobes differ only in mass and in a mean shift t J_k (u_Q - u_k). Each flake's
// images are splatted as one lobe with the mixture's mass, mean and covariance where the shifts'
// spread is below 0.1 of the lobe's std (at most about sigma_h / sigma, so every flake from a few
// texels up), else image by image. On a 256^2 map at sigma 48-200 that is 13 times faster and
// moves the images by 1e-5 to 1.5e-4 relative L1 (the folded lobes are truncated as their nearest
// image's); on 24^2 maps at sigma 5-20 the folded images are within 4e-4 of the reference's sum
// over every image. A 1024^2 map's level of sigma 512 (2 x 2 centres) took 26 s of an ndfgen bake
// of sharp flakes before.
#pragma once

#include <glintbake/bake/ndf/flakes.h>

#include <vector>

namespace glintbake::bake::ndf {

struct SplatParams {
  int ndf_res = 128;                  // R, bins per side, [2, 4096]
  double sigma_r = 0.005;             // intrinsic roughness (s-plane std), (0, 1]
  double footprint_truncation = 3.5;  // radius in units of sqrt(sigma_h^2 + sigma_p^2), [1, 10]
  double lobe_truncation = 4.0;       // lobe extent in conditional stds, [2, 10]
};

// Per-flake factors on the footprint weights of one pyramid level (footprintPartition): the flake
// at wrapped grid position (gx, gy) weighs x[gx] * y[gy] times its Gaussian weight. An empty axis
// has factor 1.
struct FootprintPartition {
  std::vector<double> x, y;
  bool empty() const { return x.empty() && y.empty(); }
};

// The factors that make a level's footprints a partition of unity on a repeating map, axis by axis
// (formats/SPEC.md 10.1): 1 / R(u) with R(u) = stride * sum_k g(u - c_k), g the normal density of
// the splat's variance sigma_h^2 + sigma^2 and c_k = (k + 0.5) stride the level's centres and their
// periodic images (R has mean 1). The level's Gaussian footprints then sum to the same weight at
// every texel, so a flat mix of its images is exactly the whole map's NDF instead of one whose
// texels weigh 1 +- 2 exp(-2 pi^2 (sigma / stride)^2) (1.4% at stride 2 sigma). An axis is left
// alone (no entries) on clamped maps, with fewer than two centres, or with a stride above
// kPartitionMaxStride times the footprint's std, where R would dip towards 0 between centres.
constexpr double kPartitionMaxStride = 2.5;
FootprintPartition footprintPartition(const FlakeSet& flakes, double sigma, int centres_x, double stride_x,
                                      int centres_y, double stride_y);

// Computes NDF images of one FlakeSet. Holds scratch buffers: one splatter per thread (not
// thread-safe); the FlakeSet is shared read-only and must outlive the splatter. Deterministic: the
// result depends only on the flakes, the parameters and the footprint (fixed flake order, double
// accumulation).
class Splatter {
 public:
  Splatter(const FlakeSet& flakes, const SplatParams& params);

  // Bin-averaged P-NDF image of the footprint centred at (x, y) texels with std sigma texels
  // (sigma >= 0) into out[R * R] (row-major, row 0 at s_y = +1). Returns the number of flakes
  // that contributed.
  // With `partition`, each flake's footprint weight is multiplied by its factors.
  int64_t image(double x, double y, double sigma, float* out, const FootprintPartition* partition = nullptr);

  // The same image split into `parts` interleaved sets of flake rows, for footprints too large for
  // one thread: accumulate() adds the bin MASSES of rows part, part + parts, ... into acc[R * R]
  // (thread-safe: const, caller-owned buffer); finish() turns summed masses into the stored image.
  // Summing the parts in a fixed order gives bytes independent of the thread count (they may differ
  // from image() in the last bits, since the summation order differs).
  int64_t accumulate(double x, double y, double sigma, int part, int parts, double* acc,
                     const FootprintPartition* partition = nullptr) const;
  void finish(const double* acc, float* out) const;
  // Flakes within the truncation radius of a footprint of std sigma (estimate, for scheduling).
  double flakesPerImage(double sigma) const;

  int resolution() const { return params_.ndf_res; }
  const SplatParams& params() const { return params_; }

  // Adds the bin masses of a Gaussian lobe N(mean, cov) times `mass` into acc[R * R] (masses, not
  // densities). cov = [[cxx, cxy], [cxy, cyy]] must be positive definite. Exposed for tests.
  static void splatLobe(double* acc, int res, double mean_x, double mean_y, double cxx, double cxy, double cyy,
                        double mass, double truncation);

 private:
  const FlakeSet& flakes_;
  SplatParams params_;
  std::vector<double> acc_;
  std::vector<uint8_t> inside_disk_;
};

}  // namespace glintbake::bake::ndf
