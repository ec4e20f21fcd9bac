// SPDX-License-Identifier: Apache-2.0
// Sharded bakes in the tools (--shard I/N; libbake/shard/shard.h has the model): the option, the
// plan of a pyramid bake's units, and the partial container a shard writes. `glintinfo merge`
// reads what ShardOutput writes (formats/SPEC.md 10.9, README "Studio scale").
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/shard/shard.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/tool.h>

#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::cli {

struct ShardCliOptions {
  std::string text;  // "I/N"; empty: no sharding
  bake::shard::ShardSpec spec;
  bool active() const { return !text.empty(); }
};

// Registers --shard I/N.
void addShardOption(CLI::App& app, ShardCliOptions& shard);
// Parses --shard (Error exit 1 naming the option when malformed).
void resolveShardOption(ShardCliOptions& shard);

// The units of a pyramid bake: every region of every level the bake may reach (levels it stops
// before hold no sections; every shard knows which), then the flakes section when written. Cost:
// centres x flakes under one footprint (its truncated extent clipped to the map). Each level is
// dealt out longest first on its own (the automatic level count may stop at any level), its
// busiest share to the shard with the least work so far; the flakes unit to the least loaded.
class PyramidShardPlan {
 public:
  PyramidShardPlan(const bake::NormalMap& map, const bake::ndf::PyramidOptions& options, bool flakes, int shards);
  size_t units() const { return owners_.size(); }
  int owner(int level, int region) const;
  int flakesOwner() const { return flakes_owner_; }  // -1 without a flakes unit
  // The unit number of a region (level-major, region order; shard-unit keys) and of the flakes
  // (the last unit; -1 without one).
  uint64_t unit(int level, int region) const { return level_base_[size_t(level)] + uint64_t(region); }
  int64_t flakesUnit() const { return flakes_owner_ < 0 ? -1 : int64_t(owners_.size()) - 1; }
  // Units of shard i and their summed cost estimate.
  uint64_t unitsOf(int shard) const;
  double costOf(int shard) const;
  // A region filter (PyramidOptions::region_filter) for shard i; the plan must outlive it.
  std::function<bool(int, int)> filter(int shard) const;

 private:
  std::vector<size_t> level_base_;     // first unit of each level
  std::vector<size_t> level_regions_;  // regions of each level
  std::vector<int> owners_;
  std::vector<double> costs_;
  int flakes_owner_ = -1;
};

// The partial container of one shard: opens `path` (kind partial) and records it as the tool's
// output; sections go through partial(); finish() stores the merged asset's metadata text and the
// partial's own metadata (identity, shard, counts), then renames into place. Failures: Error exit 2.
class ShardOutput {
 public:
  // zstd_level: the merged asset's level (its sections are encoded at it by partial()).
  ShardOutput(Tool& tool, const std::string& path, const bake::shard::ShardSpec& spec, int zstd_level);

  bake::shard::PartialWriter& partial() { return partial_; }
  // The partial container itself (replayed partials write their shard-unit sections through it).
  format::Writer& writer() { return out_.writer(); }
  // A unit's results as one shard-unit section (zstd).
  void addUnit(uint64_t unit, const void* data, size_t size);
  // asset_metadata: exactly the metadata the one-machine bake writes (replayed partials: what the
  // merge completes); units: this shard's units. assembly (replayed partials): what the merge needs
  // to replay the final assembly, recorded as the shard description's `assembly`.
  void finish(const Json& asset_metadata, format::AssetKind asset_kind, uint64_t units, uint64_t units_total,
              const Json& assembly = nullptr);
  uint64_t bytesWritten() const { return out_.bytesWritten(); }

 private:
  Tool& tool_;
  bake::shard::ShardSpec spec_;
  int zstd_level_;
  ContainerOutput out_;
  bake::shard::PartialWriter partial_;
};

}  // namespace glintbake::cli
