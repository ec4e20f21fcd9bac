// SPDX-License-Identifier: Apache-2.0
// Sharded bakes: a tool run with --shard I/N bakes a deterministic share of an asset into a
// partial container (formats/SPEC.md 10.9) and `glintinfo merge` joins the N partials into the
// asset one machine would have written, byte for byte.
//
// The model every sharded tool follows: the asset's sections (metadata aside) have fixed
// positions 0, 1, ... in the order one machine writes them. The work is cut into units (for
// pyramid kinds: one region of one level, plus the flakes section), each with an estimated cost;
// assignShards() gives every unit to one shard, balancing the estimated cost, the same way on
// every machine. A shard computes the sections of its units and writes them, encoded exactly as
// the asset stores them, at their positions (PartialWriter); sections every shard can produce
// cheaply and identically (level records) are written by all, flagged common. The merger checks
// that every position is held exactly once (or identically by all for common ones) and copies the
// stored bytes in position order.
#pragma once

#include <glintbake/bake/result.h>
#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::bake::shard {

constexpr int kMaxShards = 4096;

// Shard I of N (0 <= index < count <= kMaxShards).
struct ShardSpec {
  int index = 0;
  int count = 1;
};

// Parses "I/N" (decimal, 0-based I). kBadArgument with a message naming --shard otherwise.
Result<ShardSpec> parseShardSpec(const std::string& text);

// Owner of each unit: greedy longest-first (units by decreasing cost, ties by index, each to the
// shard with the least cost so far, ties to the lowest shard), so the assignment depends only on
// the costs and the count. Costs must be finite and >= 0.
std::vector<int> assignShards(const std::vector<double>& unit_costs, int shard_count);

// Writes the sections of one shard into a partial container (an open format::Writer of kind
// kPartial) as kSectionShardSection sections keyed by their position in the merged asset. Each
// call advances the position by one. Not thread-safe.
class PartialWriter {
 public:
  // zstd_level: the level the merged asset's sections are encoded at (the tool's --zstd-level).
  PartialWriter(format::Writer& writer, int zstd_level);

  // The section at the next position, encoded as format::Writer::addSection would store it;
  // common: every shard writes the same bytes at this position.
  BakeStatus add(uint32_t type, uint64_t key, const void* data, size_t size, bool common = false,
                 format::Codec codec = format::Codec::kZstd);
  // The next position belongs to another shard.
  void skip() { ++position_; }

  uint64_t positions() const { return position_; }  // positions passed so far
  uint64_t held() const { return held_; }           // sections written (common ones included)

 private:
  format::Writer& writer_;
  format::SectionEncoder encoder_;
  std::vector<uint8_t> stored_, payload_;
  uint64_t position_ = 0, held_ = 0;
};

}  // namespace glintbake::bake::shard
