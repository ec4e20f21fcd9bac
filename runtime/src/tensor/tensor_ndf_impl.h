// SPDX-License-Identifier: Apache-2.0
// Internal state of TensorNdf, shared by its loader (tensor_ndf_load.cpp) and its queries
// (tensor_ndf.cpp). Not installed.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/runtime/tensor_ndf.h>

#include "../heap_array.h"
#include "../pyramid_blend.h"

#include <cstddef>
#include <cstdint>
#include <new>

namespace glintbake::runtime {

struct TensorNdf::Impl {
  struct Group {
    Array<float> data;  // A, B, C, A prefix, B prefix (float32)
    CpGroupView view;
  };
  struct TLevel {
    NdfLevelRecord rec;
    Array<TensorIndexEntry> index;  // [centre * nb2 + block]
    Array<double> mass;             // raw block integral over its s-plane area (0 for blank blocks)
    Array<double> centre_mass;      // non-negative assets: the sum of each centre's block masses
  };
  // A level laid out for point queries (eval, pdf, the density of a sample), built at load: the
  // centres of one block lie side by side, so that a footprint's blend over a few hundred
  // neighbouring centres reads a few contiguous runs instead of chasing each centre's index
  // entry into its group. Exact levels (every stored block exact, tensorpack's coarse levels) of
  // at most kPointDenseBytes whose blocks are mostly stored keep their values with the centres
  // innermost; the others a copy of their stored blocks' C rows, by block. Either copy is at most
  // about the size of what the level's groups already hold, whatever the asset claims.
  struct PointSlot {
    uint32_t group = kTensorBlankGroup;  // kTensorBlankGroup: a blank block
    uint32_t row = 0;                    // the row of `rows` holding its C row
  };
  struct PointLevel {
    uint64_t centres = 0;
    bool dense = false;
    Array<float> values;     // dense: [(block * bins^2 + bj * bins + bi) * centres + centre]
    Array<PointSlot> slots;  // otherwise: [block * centres + centre]
    Array<float> rows;       // otherwise: [row * row_stride + r], the stored blocks' C rows
    int32_t row_stride = 0;  // the level's largest rank
  };
  static constexpr uint64_t kPointDenseBytes = uint64_t(64) << 20;

  // The weighted centres of the footprint blend (format::NdfPyramidBlend), as NdfPyramid blends them.
  struct Blend {
    int count = 0;
    double weight[format::kMaxBlendCentres];
    const TensorIndexEntry* index[format::kMaxBlendCentres];  // the centre's nb2 entries
    const double* mass[format::kMaxBlendCentres];             // the centre's nb2 raw masses
  };

  TensorInfoRecord info;
  int res = 0, bins = 0, nb = 0;
  int bins_shift = -1;  // log2(bins) when bins is a power of two (no integer division per query)
  uint64_t nb2 = 0;
  bool nonneg = false;
  double bin = 0.0, bin_area = 0.0;  // 2 / R, (2 / R)^2
  double inv_bin_area = 0.0;         // (R / 2)^2
  double inv_bin = 0.0;              // R / 2
  int level_count = 0;
  TLevel levels[kMaxNdfLevels];
  NdfLevelRecord level_records[kMaxNdfLevels];  // levels[l].rec, contiguous for the record checks
  PyramidBlender blender;
  uint32_t group_count = 0;
  Array<Group> groups;
  Array<TensorGroupHeader> group_headers;  // as stored, for the index-entry checks
  PointLevel point[kMaxNdfLevels];
  uint64_t blocks_kept = 0;
  uint64_t memory_bytes = 0;

  RuntimeStatus load(const format::Reader& reader);
  RuntimeStatus loadGroup(const format::Reader& reader, uint32_t g, Array<uint8_t>* scratch);
  RuntimeStatus loadIndex(const format::Reader& reader, int l, Array<uint8_t>* scratch);
  RuntimeStatus buildPointLevel(int l);

  void blend(const Footprint& fp, Blend* b) const;
  // The CpMix of block `block` of the blend (blank entries skipped).
  void mixBlock(const Blend& b, uint64_t block, CpMix* mix) const;
  // Raw (unclamped) integral of the blended block over [x0, x1] x [y0, y1] in block-local bin
  // coordinates (0 <= x0 <= x1 <= B, rows from the top), in bin-area units.
  double blockRangeIntegral(const Blend& b, uint64_t block, double x0, double x1, double y0, double y1) const;
  // Blended clamped mass of one block, max(0, sum_t w_t m_t), and of the whole blend. When
  // keepsMasses(), totalMass also writes every block's clamped mass to `masses` (room for
  // kMassBlocks; the same bits as blockMass).
  static constexpr uint64_t kMassBlocks = 256;
  bool keepsMasses() const { return nb2 <= kMassBlocks; }
  double blockMass(const Blend& b, uint64_t block) const;
  double totalMass(const Blend& b, double* masses = nullptr) const;
  // Density of sample() in bin (i, j) of the image (s-plane units); shared by pdf(). Signed models.
  double binPdf(const Blend& b, int i, int j) const;
  // Non-negative models: the blend's mass as a mixture, sum_t w_t M_t (M_t the centre's mass),
  // over its separable form, summed row by row; `rows`, when not null, gets each row's sum (room
  // for 2 kMaxBlendAxis, the rows of the parts in order).
  double mixtureMass(const format::NdfBlendLevel* parts, int count, double* rows = nullptr) const;
  // The clamped blended model value of bin (bi, bj) of block `block` (eval, pdf, a sample's
  // density), from the point levels.
  double pointValue(const format::NdfBlendLevel* parts, int count, uint64_t block, int bi, int bj) const;
  // The same for bin (i, j) of the whole R x R image.
  double imagePointValue(const format::NdfBlendLevel* parts, int count, int i, int j) const;
  // The s-plane point of a point `drawn` of block `block` (bin units within the block; null: a
  // uniform point of the block from u1, u2), and its bin (bi, bj) within the block.
  void pointInBlock(const CpBlockSample* drawn, uint64_t block, double u1, double u2, SPoint* s, int* bi,
                    int* bj) const;
  // Image bin column (or row) n -> block column `block` and bin within it `local`.
  void splitBin(int n, int* block, int* local) const {
    if (bins_shift >= 0) {
      *block = n >> bins_shift;
      *local = n & (bins - 1);
    } else {
      *block = n / bins;
      *local = n - *block * bins;
    }
  }
  // Bin of s, or -1 outside [-1, 1]^2 (as NdfPyramid).
  int binOf(double sx, double sy) const;
};

}  // namespace glintbake::runtime
