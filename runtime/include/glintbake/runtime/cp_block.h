// SPDX-License-Identifier: Apache-2.0
// Constant-cost queries on CP-compressed angular NDF blocks (Deng et al. 2022, "Constant-Cost
// Spatio-Angular Prefiltering of Glinty Appearance Using Tensor Decomposition", ACM TOG, sec. 4.3), the core that the
// tensor-ndf asset wraps.
//
// A group holds K blocks of B x B bins as a rank-R CP model (bake/tensor/cp_decomposition.h):
//     value(k, i, j) = sum_r A(i, r) B(j, r) C(k, r)        (bin column i, row j, block k)
// plus per-block 1D summed-area tables of the columns of A and B, so that the sum over any
// rectangle of bins is a rank-R product of two prefix-sum differences: O(R) whatever its size.
//
// The asset-level runtime blends up to kCpMaxBlend weighted blocks (the footprint blend over
// centres and pyramid levels, formats/SPEC.md 10.1); every query here acts on such a blend, CpMix. Blocks of
// the same group share A and B, so their C rows are summed first (weights applied): a blend of
// 8 blocks from 2 groups costs 2 rank-R products per query.
//
// Non-negativity and consistency. CP models of non-negative data may dip below zero (plain ALS).
// The queries are defined on the clamped model so that every returned density is >= 0:
//   value(i, j)       = max(0, raw value)
//   rangeAverage(...) = max(0, raw range sum) / bin count
//   sample / pdf      : a quadtree descent whose children are weighted by max(0, raw range sum);
//                       pdf(i, j) is the product of the child probabilities along the path to (i, j)
//                       and sample() returns exactly that number for the bin it lands in.
// For a non-negative model (HALS) all three agree: pdf(i, j) * blockMass() == value(i, j) and
// rangeAverage equals the mean of value over the rectangle, up to float rounding. For a signed
// model they differ where clamping bites; pdf() still matches sample() bit for bit.
//
// Units: bin coordinates; a sampled point (x, y) lies in [0, B)^2, bin (i, j) covering
// [i, i + 1) x [j, j + 1). pdf is a density per unit bin area relative to the block's clamped
// mass (it integrates to 1 over the block); the asset converts it to s-plane units.
// Cost: init O(count * R); value O(groups * R); rangeSum O(groups * R); sample and pdf
// O(ceil(log2 B) * groups * R). No allocation; CpMix lives on the stack (about 40 KiB).
//
// Exact blocks. A group whose A factor is the B x B identity (rank B) stores each of its blocks
// exactly: value(k, i, j) = C(k, i) B(j, i) (tensorpack's exact levels, formats/SPEC.md 10.4). Its
// terms do not take a group slot of the mix (a footprint may blend hundreds of them): value is
// one product per term, a range sum O(width) per term, and sample / pdf treat the block as a
// mixture of its components, the compressed part (clamped, sampled by the quadtree above) and
// each exact term (non-negative, sampled by a quadtree over that block alone), chosen by mass:
//   pdf(i, j) = (m_cp pdf_cp(i, j) + sum_t max(0, value_t(i, j))) / (m_cp + sum_t m_t).
// sample() returns exactly that number for the bin it lands in.
// Thread safety: views and mixes are immutable after init; all queries are const and reentrant.
// Untrusted input: validateCpGroupView() checks a view's sizes; the data it points to must hold
// finite values (the asset reader validates sections). Query arguments are range-checked: out-of-
// range bins give 0.
#pragma once

#include <glintbake/runtime/runtime.h>

#include <cstdint>

namespace glintbake::runtime {

constexpr int32_t kCpMaxRank = 64;
constexpr int32_t kCpMaxBins = 256;
// Most terms of a blend (the footprint blend's centres, format::kMaxBlendCentres) and most
// distinct groups among them (the blend's centres lie in a few spatial regions of two levels).
constexpr int32_t kCpMaxBlend = 968;
constexpr int32_t kCpMaxGroups = 128;

// A non-owning view of one compressed group (float32, row-major, rank entries per row):
//   a, b:                 B x R factors;  c: K x R (scales folded in);
//   a_prefix, b_prefix:   (B + 1) x R prefix sums, P[t][r] = sum_{i < t} F[i][r].
struct CpGroupView {
  int32_t bins = 0;    // B, [1, kCpMaxBins]
  int32_t rank = 0;    // R, [1, kCpMaxRank]
  int32_t blocks = 0;  // K, >= 1
  const float* a = nullptr;
  const float* b = nullptr;
  const float* c = nullptr;
  const float* a_prefix = nullptr;
  const float* b_prefix = nullptr;
  bool identity_a = false;  // A is the B x B identity (rank == bins): the blocks are stored exactly
};

// kOk, or kInvalidArgument for null pointers or sizes out of range.
RuntimeStatus validateCpGroupView(const CpGroupView& view);

// One weighted block of a blend. The weight is usually an interpolation weight in [0, 1].
struct CpBlendTerm {
  const CpGroupView* group = nullptr;
  int32_t block = 0;
  float weight = 0.0f;
  // Exact blocks only (identity_a): the block's sum over its bins when the caller has it
  // precomputed (the asset's loader does), else negative and init() forms it (O(B)).
  float mass = -1.0f;
};

// A sampled bin and point. pdf: see the header comment.
struct CpBlockSample {
  float x = 0.0f, y = 0.0f;  // [0, B), bin units
  int32_t i = 0, j = 0;      // bin containing (x, y)
  double pdf = 0.0;
};

class CpMix {
 public:
  // Builds the blend of `count` terms (count in [0, kCpMaxBlend]). Terms with weight 0 are
  // skipped, and so are terms of compressed groups beyond the first kCpMaxGroups distinct ones (only assets
  // baked with spatial regions of fewer than 4 centres per side reach that); all groups must share B and hold valid
  // views (validateCpGroupView) and the block index must be in [0, K). Returns kInvalidArgument otherwise (the mix is
  // then empty: every query returns 0). Zero terms give an empty mix.
  RuntimeStatus init(const CpBlendTerm* terms, int32_t count);

  int32_t bins() const { return bins_; }
  bool empty() const { return group_count_ == 0 && exact_count_ == 0; }

  // Unclamped model value of bin (i, j) (may be negative for signed models).
  float rawValue(int32_t i, int32_t j) const;
  // max(0, rawValue); 0 outside [0, B)^2.
  float value(int32_t i, int32_t j) const;

  // Unclamped sum over the half-open bin rectangle [i0, i1) x [j0, j1), 0 <= i0 <= i1 <= B.
  float rawRangeSum(int32_t i0, int32_t i1, int32_t j0, int32_t j1) const;
  // Average over the inclusive rectangle [i0, i1] x [j0, j1] (clipped to the block), clamped at 0:
  // max(0, rawRangeSum) / (bin count). 0 for an empty rectangle.
  float rangeAverage(int32_t i0, int32_t i1, int32_t j0, int32_t j1) const;
  // max(0, raw sum over the whole block): the weight with which an asset chooses this block.
  float blockMass() const;

  // Draws a point by quadtree descent with clamped range weights (u1 steers the column split,
  // u2 the row split, both rescaled at each level and finally used to jitter inside the bin).
  // u1, u2 in [0, 1). Returns false (and leaves *out untouched) when the block mass is 0.
  bool sample(double u1, double u2, CpBlockSample* out) const;

  // Probability density with which sample() produces a point of bin (i, j) (per unit bin area).
  // 0 outside the block or when the mass is 0.
  double pdf(int32_t i, int32_t j) const;
  // The same for a point in bin units (floor of x and y).
  double pdfAt(float x, float y) const;

 private:
  // Clamped weights of the four children of [x0, x1) x [y0, y1) split at (xm, ym), in the order
  // (left-top, right-top, left-bottom, right-bottom), of one component: the compressed groups
  // (component -1) or exact term `component`.
  void childWeights(int32_t component, int32_t x0, int32_t xm, int32_t x1, int32_t y0, int32_t ym, int32_t y1,
                    float w[4]) const;
  // The compressed groups' unclamped range sum, and exact term t's.
  float groupRangeSum(int32_t i0, int32_t i1, int32_t j0, int32_t j1) const;
  float exactRangeSum(int32_t t, int32_t i0, int32_t i1, int32_t j0, int32_t j1) const;
  float exactValue(int32_t t, int32_t i, int32_t j) const;
  // Quadtree descent within one component, and the probability it gives bin (i, j).
  bool descend(int32_t component, double u1, double u2, CpBlockSample* out) const;
  double descentPdf(int32_t component, int32_t i, int32_t j) const;
  // The clamped mass of a component (the compressed part -1, or an exact term), formed by init();
  // the mixture density of bin (i, j).
  double componentMass(int32_t component) const { return component < 0 ? group_mass_ : exact_m_[component]; }
  double mixturePdf(int32_t i, int32_t j) const;

  int32_t bins_ = 0;
  int32_t group_count_ = 0;
  int32_t exact_count_ = 0;
  // Written by init() before any read (left uninitialised: a mix is built per query).
  const CpGroupView* groups_[kCpMaxGroups];
  float coef_[kCpMaxGroups][kCpMaxRank];
  const CpGroupView* exact_[kCpMaxBlend];
  const float* exact_c_[kCpMaxBlend];  // the term's C row
  float exact_w_[kCpMaxBlend];
  double exact_m_[kCpMaxBlend];  // weighted, clamped mass of each exact term
  double group_mass_ = 0.0;      // clamped mass of the compressed groups (when exact terms are present)
  double mix_mass_ = 0.0;        // group_mass_ + sum of exact_m_
};

}  // namespace glintbake::runtime
