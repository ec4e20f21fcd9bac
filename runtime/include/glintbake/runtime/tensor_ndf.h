// SPDX-License-Identifier: Apache-2.0
// Runtime-lite reader of tensor-ndf assets (written by tensorpack): the footprint pyramid of
// ndf-pyramid assets with every NDF image cut into B x B angular blocks stored as rank-R CP models
// per group (Deng et al. 2022, "Constant-Cost Spatio-Angular Prefiltering of Glinty Appearance
// Using Tensor Decomposition", ACM TOG, sec. 4). Layout:
// formats/SPEC.md section 10.4 and tensor_ndf_layout.h.
//
// Geometry and blending are exactly those of NdfPyramid (ndf_pyramid.h): the footprint blend of
// formats/SPEC.md 10.1 (bilinear at and below sigma_0, a Gaussian-weighted mean of one or two
// levels' centres above). A point, a bin or a block of the s-plane has the same block index in all
// blended images, so every query blends the (group, row, weight) terms of one block (CpMix,
// cp_block.h), summed per group first; blank blocks contribute 0.
//
// Queries (Footprint in texels, SPoint/SRect in the s-plane, values per unit s-plane area):
//  - eval: max(0, blended model value) of the bin containing s; 0 outside [-1, 1]^2. Bins whose
//    centre lies outside the unit disk hold what the model stores there (tensorpack drops the
//    blocks entirely outside the disk; partial blocks reconstruct to about 0).
//  - average: the exact average over the rectangle of the piecewise-constant model, partial bins
//    weighted by their overlap, parts outside [-1, 1]^2 counting as 0 (NdfPyramid::average
//    semantics). Per block the rectangle touches, the integral is one rank-R product of continuous
//    cumulative sums (prefix sum of the whole bins plus the covered fraction of each end bin) and
//    is clamped at 0. Cost is independent of the rectangle size except for the number of blocks it
//    spans (at most nb^2).
//  - sample, non-negative assets (TensorInfoRecord flag bit 0, factors checked >= 0 by open()):
//    every blended term is non-negative, so the blend is the mixture sum_t w_t NDF_t. sample picks
//    a centre with probability w_t M_t / sum (M_t the centre's mass), a block of it by its mass,
//    then descends that one block's quadtree (CpMix::sample) and jitters in the bin; the density
//    reported is eval / mass, and pdf() forms the same quotient (bit for bit). Cost: eval plus a
//    walk over the centres and one centre's nb^2 masses (precomputed by open()).
//  - sample, signed models: picks a block with probability proportional to its blended clamped
//    mass max(0, sum_t w_t m_t) (8 x nb^2 x centres loads), then descends the block's blended
//    quadtree. pdf() returns exactly the density sample() reported for a point, and mass() is the
//    sum of the clamped block masses that both normalise by.
// For non-negative assets the clamps never bite and eval, average and pdf * mass agree up to float
// rounding; for signed models they differ where the model dips below 0 (then pdf * mass is not
// eval, but pdf still matches sample).
//
// Memory: every group's factors are loaded by open() (float16 factors are widened to float32),
// plus 8 bytes of index and 8 bytes of raw mass per (centre, block) and, for non-negative assets, 8
// bytes of mass per centre. Queries never allocate, never throw, are const and thread-safe. open()
// is safe on untrusted input: every record, index entry, group header and section size is checked
// (SPEC 10.4 "Readers MUST ...") and every stored value must be finite and of bounded magnitude, so
// that no query can overflow; anything else is kInvalidAsset.
#pragma once

#include <glintbake/runtime/cp_block.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/pyramid_ndf.h>
#include <glintbake/runtime/tensor_ndf_layout.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

// Largest magnitude a stored factor or prefix sum may have (keeps every rank-R product of an
// 8-term blend far below float overflow).
constexpr float kTensorMaxFactor = 1e9f;
constexpr float kTensorMaxPrefix = 1e12f;

class TensorNdf : public PyramidNdf {
 public:
  TensorNdf();
  ~TensorNdf() override;
  TensorNdf(const TensorNdf&) = delete;
  TensorNdf& operator=(const TensorNdf&) = delete;

  // open(), openMemory(), load(), isOpen(), levelCount(), level() and the argument checks of the
  // queries: pyramid_ndf.h. open() loads all groups.
  format::AssetKind kind() const override { return format::AssetKind::kTensorNdf; }

  // The asset descriptor, or null when not open.
  const TensorInfoRecord* info() const;
  int groupCount() const;
  // Runtime view of group g in [0, groupCount()) (float32 factors and prefix sums), or null.
  const CpGroupView* group(int g) const;
  // Index entry of block `block` (by * nb + bx) of centre (i, j) of level l, or null out of range.
  const TensorIndexEntry* indexEntry(int l, int i, int j, int block) const;
  // Non-blank (centre, block) entries over all levels.
  uint64_t blocksKept() const;
  // Bytes held in memory (factors, prefix sums, index, masses, and every level's layout for point
  // queries: a copy of its C rows by block, or an exact level's values with the centres innermost).
  uint64_t memoryBytes() const;

 protected:
  RuntimeStatus loadKind(const format::Reader& reader) override;
  void reset() override;
  bool loaded() const override { return impl_ != nullptr; }
  const NdfLevelRecord* levelRecords(int* count) const override;
  format::NdfPyramidBlend* blender() override;
  const format::NdfPyramidBlend* blender() const override;

  RuntimeStatus evalChecked(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus averageChecked(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sampleChecked(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdfChecked(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus massChecked(const Footprint& footprint, double* value) const override;
  RuntimeStatus imageChecked(const Footprint& footprint, float* out) const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glintbake::runtime
