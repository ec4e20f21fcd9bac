// SPDX-License-Identifier: Apache-2.0
// The final assembly of a tensor-ndf asset from per-region results: group numbering, the level
// indexes, the tensor-info record and the error statistics of the report.
//
// A tensor pack (tensor_pack.h) turns each region of each level into a RegionResult: the region's
// dropped-block statistics, the sum of its images, its index entries (group numbers local to the
// region) and its encoded groups. A TensorRegionConsumer receives them in a fixed order (for each
// level: level(), then for every region in region order region(), its groups, endRegion(); then
// endLevel()). TensorAssembler is the consumer that writes the asset; a sharded bake records the
// results of its own regions into a partial container instead, and `glintinfo merge` replays them
// through the same TensorAssembler, so the merged asset and the one-machine asset are made by one
// piece of code (formats/SPEC.md 10.9).
//
// Determinism: the assembler's sums run in region order, then group order within the region, so
// its output depends only on the results and their order, never on how they were computed.
#pragma once

#include <glintbake/bake/result.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/tensor_ndf.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glintbake::bake::tensor {

// Statistics of one encoded group (everything the assembly needs besides its bytes).
struct GroupStats {
  int rank = 0;
  int blocks = 0;              // rows of C
  double error_squared = 0.0;  // |T - stored model|_F^2
  double norm_squared = 0.0;   // |T|_F^2
  double negative_mass = 0.0;  // sum of max(0, -model)
  double absolute_mass = 0.0;  // sum of |model|
  double error_l1 = 0.0;       // sum of |T - stored model|
  double data_l1 = 0.0;        // sum of |T|
  double seconds = 0.0;        // compression time (reported, never stored)
};

// One region of one level, before its groups.
struct RegionSummary {
  int level = 0, region = 0;
  int x0 = 0, y0 = 0, width = 0, height = 0;  // its centres on the level's grid
  int group_count = 0;                        // groups that follow (0: every block blank)
  uint64_t blocks_kept = 0, blocks_dropped = 0;
  double dropped_squared = 0.0;  // sum of |block|_F^2 over the dropped blocks
  // The sum of the region's images, bin by bin (R^2 values, images added in centre order).
  const double* image_sum = nullptr;
  // width * height * nb^2 entries: centre k of the region (row-major within it), block b; group
  // is local to the region (0 .. group_count - 1) or format::kTensorBlankGroup.
  const format::TensorIndexEntry* index = nullptr;
};

// True when the level of this record is stored exactly (TensorPackOptions::exact_level_bytes):
// every kept block its own group of rank B.
bool isExactLevel(const format::NdfLevelRecord& record, const TensorPackOptions& options);

// kBadArgument unless the block side divides the NDF resolution res (>= 1) of a level.
BakeStatus checkBlockDividesResolution(int block, int res);

class TensorRegionConsumer {
 public:
  virtual ~TensorRegionConsumer() = default;
  virtual BakeStatus level(const format::NdfLevelRecord& record) = 0;
  virtual BakeStatus region(const RegionSummary& summary) = 0;
  // The next group of the current region: its section's bytes (`raw`, size raw_size), or already
  // encoded (`stored`: stored_size bytes with `codec`, as the asset stores them; raw is then null).
  virtual BakeStatus group(const GroupStats& stats, const uint8_t* raw, size_t raw_size, const uint8_t* stored,
                           size_t stored_size, format::Codec codec) = 0;
  virtual BakeStatus endRegion() = 0;
  virtual BakeStatus endLevel() = 0;
  // A region another shard computes (only in sharded bakes; the assembler never sees one).
  virtual BakeStatus skipRegion(int level, int region) { return (void)level, (void)region, okStatus(); }
};

// Writes the asset's sections in the order tensor_pack.h documents (each level's ndf-level
// record, its groups numbered 0, 1, ... across the whole asset, its tensor-index; finish() adds the
// tensor-info record) and fills a TensorPackReport (levels, groups, errors, ranks, bytes). Checks
// what it is given (kInvalidInput: a region out of order or off the level's grid, local group
// numbers or rows out of range, sizes that disagree), so it is safe on results read from untrusted
// partial containers. Not thread-safe.
class TensorAssembler final : public TensorRegionConsumer {
 public:
  TensorAssembler(format::Writer& writer, const TensorPackOptions& options, TensorPackReport& report);

  BakeStatus level(const format::NdfLevelRecord& record) override;
  BakeStatus region(const RegionSummary& summary) override;
  BakeStatus group(const GroupStats& stats, const uint8_t* raw, size_t raw_size, const uint8_t* stored,
                   size_t stored_size, format::Codec codec) override;
  BakeStatus endRegion() override;
  BakeStatus endLevel() override;
  // The tensor-info record and the report's totals. kInvalidInput when no block was kept.
  BakeStatus finish();

 private:
  BakeStatus writeSection(uint32_t type, uint64_t key, const void* data, size_t size);

  format::Writer& writer_;
  TensorPackOptions options_;
  TensorPackReport& report_;
  int ndf_res_ = 0, blocks_per_side_ = 0;
  int level_ = -1;
  format::NdfLevelRecord record_;
  bool in_region_ = false;
  int next_region_ = 0;
  RegionSummary region_;
  std::vector<int> region_rows_;  // rows each local group of the current region must have
  int region_groups_seen_ = 0;
  uint64_t region_first_group_ = 0;
  uint64_t level_bytes_before_ = 0, bytes_at_start_ = 0;
  std::vector<format::TensorIndexEntry> index_;  // of the current level
  std::vector<double> level_sum_;
  uint64_t level_images_ = 0;
  double absolute_mass_ = 0.0;
};

}  // namespace glintbake::bake::tensor
