// SPDX-License-Identifier: Apache-2.0
// Records of tensor-ndf assets (formats/SPEC.md section 10.4), written by the tensor-ndf packer
// (libbake, tensorpack), read by the runtime. Stored as the raw little-endian bytes of the structs.
//
// A tensor-ndf asset is an ndf-pyramid whose NDF images are cut into B x B angular blocks and
// compressed per group (one spatial region of one level) by a rank-R CP decomposition:
//  - section 16 `ndf-level` (key = level): the pyramid geometry, an NdfLevelRecord
//    (kinds/ndf_pyramid.h); region_size there is the grouping region;
//  - section 33 `tensor-info` (key 0): one TensorInfoRecord;
//  - section 32 `tensor-index` (key = level): for every centre of the level (row-major over the
//    level's grid) and every block of its image (row-major, block (bx, by) = by * nb + bx, bx from
//    the left at s_x = -1, by from the top at s_y = +1, nb = R / B), a TensorIndexEntry;
//  - section 34 `tensor-group` (key = group id, 0 .. group_count - 1): a TensorGroupHeader followed
//    by the factors (see TensorGroupHeader).
#pragma once

#include <glintbake/format/kinds/ndf_pyramid.h>
#include <glintbake/format/records.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

constexpr uint32_t kTensorMaxRank = 64;        // largest group rank
constexpr uint32_t kTensorMaxBlockBins = 256;  // largest block side B

// Asset descriptor (64 bytes).
struct TensorInfoRecord {
  uint32_t magic = 0x494E5447;  // "GTNI"
  uint32_t version = 1;
  uint32_t ndf_res = 0;          // R, bins per side of the NDF images (equal to every level's ndf_res)
  uint32_t block = 0;            // B, bins per side of a block; divides R
  uint32_t blocks_per_side = 0;  // nb = R / B
  uint32_t level_count = 0;      // levels (ndf-level and tensor-index sections 0 .. level_count - 1)
  uint32_t group_count = 0;      // tensor-group sections 0 .. group_count - 1
  uint32_t max_rank = 0;         // largest rank of any group, [1, kTensorMaxRank]
  uint32_t precision = 0;        // factor storage: 0 = float32, 1 = float16 (prefix sums are float32)
  uint32_t flags = 0;            // bit 0: non-negative factors (every range sum >= 0)
  double blank_threshold = 0.0;  // blocks whose mass (integral over the block) was below this were dropped
  uint64_t reserved[2] = {0, 0};
};
static_assert(sizeof(TensorInfoRecord) == 64, "TensorInfoRecord is 64 bytes");

constexpr uint32_t kTensorFlagNonNegative = 1u;
constexpr uint32_t kTensorBlankGroup = 0xFFFFFFFFu;  // TensorIndexEntry::group of a dropped (all-zero) block

// Where one block of one centre's image lives (8 bytes).
struct TensorIndexEntry {
  uint32_t group = kTensorBlankGroup;  // group id, or kTensorBlankGroup: the block is 0 everywhere
  uint32_t row = 0;                    // row of the group's C matrix, [0, blocks)
};
static_assert(sizeof(TensorIndexEntry) == 8, "TensorIndexEntry is 8 bytes");

// Header of a tensor-group section (32 bytes). It is followed by, with E = 4 bytes (precision 0)
// or 2 bytes (precision 1, IEEE binary16, binary16.h):
//   A          bins x rank values (E each), row-major: A(i, r) at [i * rank + r]  (bin column i)
//   B          bins x rank values (E each): B(j, r) (bin row j, top row j = 0)
//   C          blocks x rank values (E each): C(k, r), column scales folded in
//   A_prefix   (bins + 1) x rank float32: A_prefix[t][r] = sum_{i < t} A(i, r) (of the stored values)
//   B_prefix   (bins + 1) x rank float32
// The density of bin (i, j) of the block at row k is sum_r A(i, r) B(j, r) C(k, r), in the units
// of NDF images (density per unit s-plane area, formats/SPEC.md section 3.1).
struct TensorGroupHeader {
  uint32_t magic = 0x474E5447;  // "GTNG"
  uint32_t bins = 0;            // B (equals TensorInfoRecord::block)
  uint32_t rank = 0;            // R of this group, [1, TensorInfoRecord::max_rank]
  uint32_t blocks = 0;          // K, rows of C, >= 1
  uint32_t level = 0;           // pyramid level of the group's centres
  uint32_t region = 0;          // ry * regions_x + rx on that level
  uint32_t precision = 0;       // equals TensorInfoRecord::precision
  uint32_t reserved = 0;
};
static_assert(sizeof(TensorGroupHeader) == 32, "TensorGroupHeader is 32 bytes");

// Bytes of a tensor-group section with these fields (header, factors, prefix sums).
constexpr uint64_t tensorGroupSectionBytes(uint64_t bins, uint64_t rank, uint64_t blocks, uint32_t precision) {
  return sizeof(TensorGroupHeader) + (precision == 1 ? 2 : 4) * (2 * bins + blocks) * rank + 4 * 2 * (bins + 1) * rank;
}

// Checks the info record: magic and version, R in [2, kMaxNdfResolution], B in
// [1, kTensorMaxBlockBins] dividing R with nb = R / B, level_count in [1, kMaxNdfLevels], max_rank
// in [1, kTensorMaxRank], precision 0 or 1, no unknown flag, finite blank_threshold.
RecordCheck checkTensorInfoRecord(const TensorInfoRecord& info);

// Checks a level record of a tensor-ndf asset: checkNdfLevelRecord, and R equal to the info's.
RecordCheck checkTensorLevelRecord(const NdfLevelRecord& record, uint32_t key, const TensorInfoRecord& info,
                                   const NdfLevelRecord* below);

// Checks a group header against the (checked) info record and the level records `levels`
// (info.level_count of them, checked): magic, bins = B, rank in [1, max_rank], blocks >= 1 and at
// most the blocks of region_size^2 centres, level < level_count, region on that level, precision
// equal to the info's, reserved 0. The section must then be tensorGroupSectionBytes() long.
RecordCheck checkTensorGroupHeader(const TensorGroupHeader& header, const TensorInfoRecord& info,
                                   const NdfLevelRecord* levels);

// Checks one index entry of level `level`, centre region `region`, against the group headers
// (group_count of them, each checked): blank, or a group of that level and region and a row below
// its block count.
inline RecordCheck checkTensorIndexEntry(const TensorIndexEntry& entry, const TensorGroupHeader* groups,
                                         uint32_t group_count, uint32_t level, uint32_t region) {
  if (entry.group == kTensorBlankGroup) return recordOk();
  if (entry.group >= group_count) return recordInvalid("index entry names a missing group");
  const TensorGroupHeader& g = groups[entry.group];
  if (entry.row >= g.blocks || g.level != level || g.region != region)
    return recordInvalid("index entry disagrees with its group");
  return recordOk();
}

}  // namespace glintbake::format
