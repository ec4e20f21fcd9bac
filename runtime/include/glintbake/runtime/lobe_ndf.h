// SPDX-License-Identifier: Apache-2.0
// The P-NDF of mid-size footprints from clustered position-normal lobes: a hierarchy over tiles
// of a normal map's flakes in which every tile keeps a few 4D Gaussians in (position, normal) that
// stand for all of its flakes (formats/SPEC.md 10.5).
//
// A flake of the exact path (flake_ndf.h) is itself a 4D Gaussian: position u ~ N(u_k, sigma_h^2 I)
// and normal s = n_k + J_k (u - u_k) + N(0, sigma_r^2 I), so that its covariance is
//   S_uu = sigma_h^2 I,  S_su = sigma_h^2 J_k,  S_ss = sigma_r^2 I + sigma_h^2 J_k J_k^T
// (Yan et al. 2016, "Position-Normal Distributions for Efficient Rendering of Specular
// Microstructure", section 4). A group of flakes is replaced by the Gaussian with the group's
// weight, mean and covariance (the moments of the mixture, so a group keeps exactly the first two
// moments of its flakes, and a group of one flake is that flake). Seen through a Gaussian footprint
// of std sigma_p centred at u_Q, a lobe with weight W, mean (c, m) and covariance S contributes
//   W N(u_Q; c, A) N(s; m + S_su A^-1 (u_Q - c), S_ss - S_su A^-1 S_us),   A = S_uu + sigma_p^2 I,
// which is the exact closed form of flake_ndf.h for a single flake.
//
// The hierarchy: level 0 tiles hold 4 x 4 flakes, every level doubles the tile side up to the
// whole map. A tile of level 0 groups its flakes, a tile above groups the lobes of its four
// children, each into at most `lobes_per_tile` lobes by greedy pairwise merging: the pair whose
// moment-matched union raises the Kullback-Leibler bound of Runnalls (2007, "Kullback-Leibler
// approach to Gaussian mixture reduction") least on the normal marginals is merged until the tile
// keeps lobes_per_tile (lobes of different orientation stay apart, as the arms of two crossing
// scratches, which k-means on the normal means merged; image relative L1 at 24 texels against
// every flake as its own lobe, k-means -> this: curved scratches 0.159 -> 0.057, sharp flakes
// 0.144 -> 0.034, leather 0.087 -> 0.066, on the 1024^2 and 512^2 maps of the README).
//
// A footprint is answered from a cut through the hierarchy: near its centre the tiles of the
// level whose tiles are at most the tile ratio (0.35 by default, setTileRatio; an asset's flakes
// record may ask for less) times its std (so the footprint weight varies little across a tile),
// farther out coarser ones, a tile k levels up (k <= 3) where its nearest point lies at
// least sqrt(2 k) standard deviations from the centre, where the weight has fallen below e^-k of
// its peak; every lobe within 3 standard deviations of the centre counts. The cut depends on the
// footprint only, so eval, mass, sample and the images see the same lobes. It visits about
// 140-370 tiles where the answering level alone spans 300-1200 (a disk of 3 sigma on tiles of
// 0.175-0.35 sigma), at a cost in image relative L1 against the reference of at most 0.024 on the
// README's maps (sharp flakes at 24 texels, 0.032 -> 0.056; leather at 32, 0.070 -> 0.077; the
// smooth maps unchanged); coarser tiles from 1 standard deviation on doubled that error. Each
// query gathers the tiles of its cut by their geometry and prefetches their blocks a few tiles
// ahead of the kernel (the blocks, about a kilobyte each, are scattered over the levels): 0.6-0.7
// times the time of the cut without it. Every tile of the cut goes to the kernel: a test of each
// tile's box of lobe means skipped few and cost more than it saved (eval 0.76-0.86x the time
// without it at 24-48 texels). The kernel has two passes (a division-free test, then exp and
// sqrt on the kept lobes only; AVX2 where the processor has it, with the same bits as the SSE2
// kernel). With lobes_per_tile = 16, level 0 keeps every flake as its own lobe. Below 0.35 x
// sigma_p = 4 flakes (11.4 texels at one flake per texel, at the default tile ratio) its eval,
// mass and sampling are those of the exact flakes (flake_ndf.h, which prunes by normal within
// tiles) with the 3-sigma window, without a cut. From there to the first clustered level (22.9
// texels) level 0 takes the cut as the others do, and the tiles it would split into level-0 tiles
// (the level-1 tiles within sqrt(2) sigma_p of the centre, which lie inside the window's disk) are
// answered by the exact flakes' evaluator restricted to them: their eval prunes by normal, their
// mass is a product of running sums along the axes, and a sample picks one of them by that mass,
// then a row, then a flake; average and image walk the same tiles as level-0 lobes (the same
// flakes). Against the whole window of exact flakes this is 0.6-0.73x the eval time at 16-22
// texels and costs 0.01-0.02 in image relative L1 on the README's maps (0.003-0.017 ->
// 0.017-0.027 at 12-20 texels); a cut from 1 standard deviation saved another 12-17% at
// 0.01-0.017 more. On 1024^2 maps
// (bench/bench_flakes.cpp) eval costs about 4 us at sigma_p = 6 texels, 14-21 us at 12-16 and
// 32-34 us at 22 (the costliest band, 44-57 us without the cut) and 8.4-9.7 us on the clustered
// levels at 24 and 48 (21-25 and 16-17 before the cut). Sample: on level 0 the disk rows' weights
// come from running sums of the column weights (linear in the window's side), so it costs about
// one eval, 1.4-1.5 evals with the cut; on the clustered levels one weighing of the cut's tiles
// (AVX2 where the processor has it), whose tile masses the pick reuses, plus the eval of its
// density: about 2 evals.
//
// What it gives up against the exact path: the shape of each group beyond its covariance. It is
// close where a tile's flakes form a few tight groups (sharp flakes, scratches) or vary smoothly,
// and measured against the reference evaluator by scripts/fidelity.py (README, "Figures").
//
// Queries follow the NdfSource contract as the exact path does (eval the sum of the lobes, average
// and image their exact integrals over rectangles and bins, mass the sum of the footprint weights,
// sample a lobe by weight then its Gaussian with pdf = eval / mass). Queries never allocate, never
// throw and are thread-safe (const).
#pragma once

#include <glintbake/format/kinds/flakes.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/texel_source.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

// Lobes a tile keeps at most (the width of the evaluator's blocks).
constexpr int kMaxLobesPerTile = 16;

// The cut answers a footprint of std sigma from tiles of at most tile ratio x sigma per side near
// its centre (coarser ones farther out): the default, and the range setTileRatio accepts
// (formats/SPEC.md 10.5, the flakes record's tile_ratio).
constexpr double kDefaultLobeTileRatio = format::kDefaultFlakesTileRatioMilli / 1000.0;
constexpr double kMinLobeTileRatio = format::kMinFlakesTileRatioMilli / 1000.0;
constexpr double kMaxLobeTileRatio = format::kMaxFlakesTileRatioMilli / 1000.0;

class LobeNdf final : public AccumulatingNdfSource {
 public:
  LobeNdf();
  ~LobeNdf() override;
  LobeNdf(const LobeNdf&) = delete;
  LobeNdf& operator=(const LobeNdf&) = delete;

  // Builds the lobe hierarchy from a texel source with the flake model of flake_ndf.h: rate flakes
  // per texel side (1..16), intrinsic roughness sigma_r in (0, 1], lobes_per_tile in
  // [1, kMaxLobesPerTile], image resolution R (2..4096). Memory, all of it allocated here: at 16
  // lobes per tile about 63 bytes per flake at one flake per texel (the levels above the finest 20,
  // the exact flakes 35, and the normals, 8 bytes a texel, from which the finest level's tiles are
  // made when they are needed: 60 bytes a flake less than storing them, the same bits); with fewer
  // lobes per tile about 80 (the finest level stored, grouped). build() groups the finest level
  // only, when it is stored; each level above is grouped from the one below on the first query
  // that needs it (thread-safe; concurrent queries of that level wait for it), so a reader that
  // never asks for mid-size footprints never pays for them. All levels
  // cost about 1.5 s for a 1024^2 map on one core (bench_flakes lobe_build; most of it the merge
  // costs of the reduction, vectorised, and level 1 three quarters of that), a sixteenth of that
  // for 256^2. kInvalidArgument for parameters out of range, non-finite normals or a source larger
  // than 65536 texels per side or 2^30 flakes; kOutOfMemory.
  RuntimeStatus build(const TexelSource& source, int rate, double sigma_r, int lobes_per_tile, int resolution);
  bool isBuilt() const;
  // Groups every level now rather than at first use (for a renderer that wants no pause in its
  // first frame). Thread-safe; a no-op when built already or not built.
  void prepare() const;

  format::AssetKind kind() const override { return format::AssetKind::kUnknown; }
  int resolution() const override;
  // The footprints the hierarchy answers: up to where its window would span more than 40 tiles of
  // the top level per side (clustered_max_sigma); larger footprints return kInvalidArgument.
  FootprintRange footprintRange() const override;
  MapSize mapSize() const override;
  MapWrap wrap() const override;
  // Tile side (flakes) of the level that answers a footprint of this sigma.
  int tileFor(double sigma) const;
  // The largest tile side, as a fraction of the footprint's std, that answers near a footprint's
  // centre: the default kDefaultLobeTileRatio; smaller ratios answer from finer tiles, closer to
  // the exact flakes where a map's tiles hold more distinct normals than a tile keeps lobes (a
  // ratio of one half costs about four times the eval). kInvalidArgument outside
  // [kMinLobeTileRatio, kMaxLobeTileRatio] or when not built. Not thread-safe: set it before
  // the hierarchy is shared; build() resets it to the default.
  RuntimeStatus setTileRatio(double ratio);
  double tileRatio() const;
  // Bytes the hierarchy holds (every level's blocks and bounds, allocated at build, and the normals
  // the finest level is made from at 16 lobes per tile); not the exact flakes. 0 when not built.
  uint64_t memoryBytes() const;

  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus mass(const Footprint& footprint, double* value) const override;
  RuntimeStatus addImage(const Footprint& footprint, double weight, float* out, size_t out_count) const override;

 private:
  friend struct LobeNdfAccess;  // the runtime's hand-over (internal)
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glintbake::runtime
