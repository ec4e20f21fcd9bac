// SPDX-License-Identifier: Apache-2.0
// Sharded tensor-ndf bakes (formats/SPEC.md 10.9, "replayed partials"). A shard cannot write the
// asset's sections: group numbers, indexes, the info record and the flakes hand-over depend on
// every region's compression. So a shard records the results of its regions (TensorShardRecorder,
// a TensorRegionConsumer) and the merge replays them, region by region in the asset's order,
// through the TensorAssembler the one-machine bake uses (replayTensorRegion): the two cannot drift.
#pragma once

#include <glintbake/bake/result.h>
#include <glintbake/bake/tensor/tensor_assembly.h>
#include <glintbake/format/container.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace glintbake::bake::tensor {

// Writes each region it is given as a shard-unit section (key = unit_of(level, region)) of an open
// partial container, its groups encoded at asset_zstd_level exactly as the asset stores them, and,
// at finish(), the level records as the shard-levels section. Not thread-safe.
class TensorShardRecorder final : public TensorRegionConsumer {
 public:
  // block: TensorPackOptions::block of the bake.
  TensorShardRecorder(format::Writer& partial, int asset_zstd_level, int block,
                      std::function<uint64_t(int, int)> unit_of);

  BakeStatus level(const format::NdfLevelRecord& record) override;
  BakeStatus region(const RegionSummary& summary) override;
  BakeStatus group(const GroupStats& stats, const uint8_t* raw, size_t raw_size, const uint8_t* stored,
                   size_t stored_size, format::Codec codec) override;
  BakeStatus endRegion() override;
  BakeStatus endLevel() override { return okStatus(); }
  BakeStatus finish();

  uint64_t regionsHeld() const { return regions_; }
  const std::vector<format::NdfLevelRecord>& levels() const { return levels_; }

 private:
  format::Writer& writer_;
  format::SectionEncoder encoder_;
  int block_;
  std::function<uint64_t(int, int)> unit_of_;
  std::vector<format::NdfLevelRecord> levels_;
  std::vector<uint8_t> head_, groups_, bytes_, stored_;
  uint64_t unit_ = 0, regions_ = 0;
};

// Hands the region of one shard-unit (`data`, `size` bytes, untrusted) to a consumer: region(), its
// groups, endRegion(). kInvalidInput naming the problem when the unit is malformed.
BakeStatus replayTensorRegion(const uint8_t* data, size_t size, TensorRegionConsumer& consumer);

}  // namespace glintbake::bake::tensor
