// SPDX-License-Identifier: Apache-2.0
// The exact P-NDF of small footprints, evaluated from the flakes of a normal map (Yan et al. 2016,
// "Position-Normal Distributions for Efficient Rendering of Specular Microstructure", sections 4-5).
//
// Every texel (or rate^2 sub-samples of it) is a 4D Gaussian flake with position u_k, normal n_k
// (bilinear interpolation of the texels at u_k) and Jacobian J_k (central differences of that
// interpolant, one texel on each side), spatial std sigma_h = 1.5 step / sqrt(12) and area
// step^2 (formats/SPEC.md 10.5; the reference evaluator in libbake/reference defines the same
// model). Seen through a Gaussian footprint of std sigma_p centred at u_Q, flake k contributes the
// closed form
//   D_k(s) = A N(u_k; u_Q, (sigma_h^2 + sigma_p^2) I) N(s; mu_k, C_k),
//   mu_k = n_k + J_k (sigma_h^2 / (sigma_h^2 + sigma_p^2)) (u_Q - u_k),
//   C_k  = sigma_r^2 I + (sigma_h^2 sigma_p^2 / (sigma_h^2 + sigma_p^2)) J_k J_k^T,
// summed over the flakes whose centre lies within 6 sqrt(sigma_h^2 + sigma_p^2) texels of u_Q
// along each axis (a square window; the reference's disk of the same radius differs by less than
// 1e-7 of the mass). With a repeating map every periodic image of a flake inside the window counts.
//
// Cost: the flakes are stored in tiles of 8 x 8, each split into 8 leaves of 2 x 4 neighbouring
// flakes; every tile keeps its normal box and largest |J_k|, every leaf its normal box, largest
// |J_k| and box of positions. A point query tests the tiles of the window, then four
// leaves at a time, and evaluates only the leaves whose lobes can reach s (spatial plus lobe
// exponent below 18); the leaves of a batch of tiles are prefetched together. Their flakes go
// through a two-pass kernel (a division-free test, then exp and sqrt on the kept flakes only), in
// AVX2 where the processor has it (chosen at run time; the same bits as the SSE2 kernel). It grows
// with sigma_p^2 times the share of flakes near s: on 1024^2 maps about 0.6-0.9 us at
// sigma_p = 0, 1.5-2 us at 1 texel, 7-11 us at 4 and 20-40 us at 8 (bench/bench_flakes.cpp).
// mass() and sample() sum the separable footprint weights by a product recurrence (an exp every
// 16 flakes), so that sampling costs little more than the eval of its pdf; the narrower disk
// windows of the clustered lobes' exact level weigh each row from running sums of the column
// weights, in time linear in the window's side.
//
// Queries follow the NdfSource contract: eval() is the closed form inside [-1, 1]^2 and 0 outside;
// average() its exact mean over a rectangle (numerical integration to about 1e-10 of each lobe's
// mass); image() the bin averages of eval, with bins whose centre lies outside the unit disk set to
// 0 as in every stored NDF image; mass() the sum of the flakes' footprint weights (the integral of
// the closed form over the whole plane); sample() picks a flake in proportion to its weight, then
// a point of its Gaussian lobe, and returns pdf = eval / mass. A point drawn outside [-1, 1]^2 (a
// lobe tail beyond the square, rare for real maps) comes back with pdf 0: treat it as a failed sample.
// Queries never allocate, never throw and are thread-safe (const).
#pragma once

#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/texel_source.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

// Largest window a query accepts, in flakes per side (about sigma_p = 340 texels at rate 1);
// larger footprints return kInvalidArgument (answer them from a pyramid).
constexpr int64_t kMaxFlakeWindow = 4096;
// Spatial truncation radius of a query's window, in footprint stds sqrt(sigma^2 + sigma_h^2), as
// the reference evaluator's: a window is 2 x this x that std x rate flakes across.
constexpr double kFlakeWindowSigmas = 6.0;

// The kernels of FlakeNdf and LobeNdf use AVX2 where the processor has it (chosen at run time, no
// -march flag needed; they give the same bits as the portable SSE2 or scalar kernels). true
// restricts both to the portable kernels (tests, benchmarks); it applies to the queries that
// start afterwards and is safe to call from any thread.
void usePortableFlakeKernels(bool portable);

class FlakeNdf final : public AccumulatingNdfSource {
 public:
  FlakeNdf();
  ~FlakeNdf() override;
  FlakeNdf(const FlakeNdf&) = delete;
  FlakeNdf& operator=(const FlakeNdf&) = delete;

  // Builds the flakes and their hierarchy from a texel source: rate flakes per texel side (1..16),
  // intrinsic roughness sigma_r in (0, 1], image resolution R (2..4096) reported by resolution()
  // and used by image(). Memory: about 35 bytes per flake. kInvalidArgument for parameters out of
  // range or a source larger than 65536 texels per side or 2^30 flakes; kOutOfMemory.
  RuntimeStatus build(const TexelSource& source, int rate, double sigma_r, int resolution);
  bool isBuilt() const;

  // kUnknown: the flakes are a part of an asset (openNdfAsset wraps them with its pyramid).
  format::AssetKind kind() const override { return format::AssetKind::kUnknown; }
  int resolution() const override;
  // Exact at every footprint up to the window limit (exact_max_sigma; no pyramid).
  FootprintRange footprintRange() const override;
  MapSize mapSize() const override;
  MapWrap wrap() const override;
  double sigmaR() const;

  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus mass(const Footprint& footprint, double* value) const override;
  // image() and addImage() cost every flake of the window (no pruning by s): a few milliseconds at
  // sigma_p = 8 texels.
  RuntimeStatus addImage(const Footprint& footprint, double weight, float* out, size_t out_count) const override;

 private:
  friend struct FlakeNdfAccess;  // the runtime's clustered lobes (internal)
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glintbake::runtime
