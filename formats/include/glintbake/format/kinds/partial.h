// SPDX-License-Identifier: Apache-2.0
// The partial kind (formats/SPEC.md 10.9): one shard of a sharded bake. A tool run with
// --shard I/N bakes a deterministic share of an asset's sections into a partial container;
// `glintinfo merge` puts the N partials back together into the asset, byte for byte the file one
// machine would have written. A partial is never an asset: the runtime refuses to open it.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/kinds/tensor_ndf.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

// Section types of replayed partials (block 144-159; container.h holds 144 and 145).
constexpr uint32_t kSectionShardUnit = 146;    // the results of one unit of work (key = unit)
constexpr uint32_t kSectionShardLevels = 147;  // the level records every shard computes (key = 0)

// Flags of a ShardSectionHeader.
constexpr uint32_t kShardSectionCommon = 1;  // every shard holds this section, with the same bytes

// Header of a shard-section (kSectionShardSection, key = the section's position in the merged
// asset, 0-based, the metadata not counted), 40 bytes little-endian, followed by stored_size
// bytes: the section exactly as the merged asset stores it (already encoded with `codec`). The
// shard-section itself is stored raw.
struct ShardSectionHeader {
  uint32_t magic = 0x53484753;  // "SGHS"
  uint32_t flags = 0;           // kShardSectionCommon, or 0 for a section only its owner holds
  uint32_t type = 0;            // the section's type in the merged asset
  uint32_t codec = 0;           // Codec of the stored bytes
  uint64_t key = 0;             // the section's key in the merged asset
  uint64_t raw_size = 0;        // decoded size
  uint64_t stored_size = 0;     // bytes that follow this header
};
static_assert(sizeof(ShardSectionHeader) == 40, "ShardSectionHeader is 40 bytes");

// Checks a header read from a shard-section of section_raw_size bytes: magic, known flags and
// codec, stored_size equal to the bytes that follow, raw_size equal to stored_size for raw sections
// and within kDefaultMaxRawSectionSize. Returns null when valid, else a one-line reason. Safe on
// untrusted input.
const char* checkShardSectionHeader(const ShardSectionHeader& header, uint64_t section_raw_size);

// Replayed partials (SPEC.md 10.9). Assets whose sections depend on every unit's results (tensor-ndf:
// group numbers, indexes, the info record and the flakes hand-over) are not cut into positions: a
// shard stores each unit's results as a shard-unit section (kSectionShardUnit, key = unit) and the
// level records as one shard-levels section (kSectionShardLevels, key 0, NdfLevelRecords one after
// another), and the merge replays the final assembly from them.
//
// The shard-unit of one region of a tensor-ndf bake (little-endian, stored with zstd):
//   TensorShardRegionRecord
//   image_sum   ndf_res^2 float64: the sum of the region's images, bin by bin (centre order)
//   index       width x height x blocks_per_side^2 TensorIndexEntry (kinds/tensor_ndf.h): centre k
//               of the region (row-major within it), block b; group local to the region
//   groups      group_count TensorShardGroupRecord
//   bytes       each group's tensor-group section as the asset stores it (stored_size bytes with
//               `codec`), in group order
struct TensorShardRegionRecord {
  uint32_t magic = 0x52535447;  // "GTSR"
  uint32_t version = 2;         // 2: group records carry the L1 error (1: without it, refused)
  uint32_t level = 0, region = 0;
  uint32_t x0 = 0, y0 = 0, width = 0, height = 0;  // the region's centres on the level's grid
  uint32_t ndf_res = 0, blocks_per_side = 0;
  uint32_t group_count = 0;
  uint32_t reserved = 0;
  uint64_t blocks_kept = 0, blocks_dropped = 0;
  double dropped_squared = 0.0;  // sum of |block|_F^2 over the dropped blocks
};
static_assert(sizeof(TensorShardRegionRecord) == 72, "TensorShardRegionRecord is 72 bytes");

struct TensorShardGroupRecord {
  uint32_t rank = 0, blocks = 0;
  uint32_t codec = 0, reserved = 0;
  uint64_t raw_size = 0, stored_size = 0;
  double error_squared = 0.0, norm_squared = 0.0;   // |T - stored model|_F^2, |T|_F^2
  double negative_mass = 0.0, absolute_mass = 0.0;  // sums of max(0, -model) and |model|
  double error_l1 = 0.0, data_l1 = 0.0;             // sums of |T - stored model| and |T|
};
static_assert(sizeof(TensorShardGroupRecord) == 80, "TensorShardGroupRecord is 80 bytes");

// Where the parts of a region's shard-unit lie (byte offsets into it).
struct TensorShardRegionLayout {
  TensorShardRegionRecord record;
  size_t image_sum = 0, index = 0, groups = 0, bytes = 0;
  uint64_t index_entries = 0;
};

// Checks a region shard-unit of `size` bytes: magic, version, reserved 0, ndf_res in
// [2, kMaxNdfResolution], blocks_per_side >= 1 dividing it, a region of at most 256 x 256 centres,
// group_count at most the kept blocks, every group record's codec known, raw sizes within
// kDefaultMaxRawSectionSize and the bytes adding up to the section exactly. Fills *layout. Returns
// null when valid, else a one-line reason. Safe on untrusted input (no overflow).
const char* checkTensorShardRegion(const uint8_t* data, size_t size, TensorShardRegionLayout* layout);

}  // namespace glintbake::format
