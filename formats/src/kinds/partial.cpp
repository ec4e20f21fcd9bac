// SPDX-License-Identifier: Apache-2.0
// Checks of the partial kind's records (see kinds/partial.h).
#include <glintbake/format/kinds/partial.h>
#include <glintbake/format/kinds/tensor_ndf.h>

#include <cstring>

namespace glintbake::format {

const char* checkShardSectionHeader(const ShardSectionHeader& h, uint64_t section_raw_size) {
  if (h.magic != ShardSectionHeader().magic) return "shard-section: bad magic";
  if ((h.flags & ~kShardSectionCommon) != 0) return "shard-section: unknown flags";
  if (h.codec != uint32_t(Codec::kRaw) && h.codec != uint32_t(Codec::kZstd)) return "shard-section: unknown codec";
  if (section_raw_size < sizeof(ShardSectionHeader) || h.stored_size != section_raw_size - sizeof(ShardSectionHeader))
    return "shard-section: stored size disagrees with the section size";
  if (h.raw_size > kDefaultMaxRawSectionSize) return "shard-section: raw size too large";
  if (h.codec == uint32_t(Codec::kRaw) && h.raw_size != h.stored_size)
    return "shard-section: raw section whose raw size differs from its stored size";
  if (h.type == kSectionMetadata) return "shard-section: holds a metadata section";
  return nullptr;
}

const char* checkTensorShardRegion(const uint8_t* data, size_t size, TensorShardRegionLayout* layout) {
  TensorShardRegionRecord r;
  if (!data || size < sizeof(r)) return "shard-unit: truncated region record";
  std::memcpy(&r, data, sizeof(r));
  if (r.magic != TensorShardRegionRecord().magic || r.version != TensorShardRegionRecord().version || r.reserved != 0)
    return "shard-unit: bad region record";
  if (r.ndf_res < 2 || r.ndf_res > kMaxNdfResolution || r.blocks_per_side < 1 || r.ndf_res % r.blocks_per_side != 0)
    return "shard-unit: NDF resolution or blocks out of range";
  if (r.width < 1 || r.height < 1 || r.width > 256 || r.height > 256) return "shard-unit: region size out of range";
  const uint64_t nb2 = uint64_t(r.blocks_per_side) * r.blocks_per_side;
  const uint64_t entries = uint64_t(r.width) * r.height * nb2;
  if (r.blocks_kept > entries || r.blocks_dropped != entries - r.blocks_kept || r.group_count > r.blocks_kept)
    return "shard-unit: block counts disagree";
  const uint64_t sum_bytes = uint64_t(r.ndf_res) * r.ndf_res * sizeof(double);
  const uint64_t index_bytes = entries * sizeof(TensorIndexEntry);
  const uint64_t group_bytes = uint64_t(r.group_count) * sizeof(TensorShardGroupRecord);
  uint64_t at = sizeof(r) + sum_bytes + index_bytes + group_bytes;
  if (at > size) return "shard-unit: truncated region";
  uint64_t stored = 0;
  for (uint32_t g = 0; g < r.group_count; ++g) {
    TensorShardGroupRecord gr;
    std::memcpy(&gr, data + sizeof(r) + sum_bytes + index_bytes + uint64_t(g) * sizeof(gr), sizeof(gr));
    if (gr.codec != uint32_t(Codec::kRaw) && gr.codec != uint32_t(Codec::kZstd)) return "shard-unit: unknown codec";
    if (gr.reserved != 0 || gr.raw_size > kDefaultMaxRawSectionSize || gr.stored_size > size)
      return "shard-unit: bad group record";
    if (gr.codec == uint32_t(Codec::kRaw) && gr.raw_size != gr.stored_size)
      return "shard-unit: raw group whose raw size differs from its stored size";
    stored += gr.stored_size;
    if (stored > size) return "shard-unit: group bytes beyond the section";
  }
  if (at + stored != size) return "shard-unit: group bytes disagree with the section size";
  if (layout) {
    layout->record = r;
    layout->image_sum = sizeof(r);
    layout->index = size_t(sizeof(r) + sum_bytes);
    layout->groups = size_t(sizeof(r) + sum_bytes + index_bytes);
    layout->bytes = size_t(at);
    layout->index_entries = entries;
  }
  return nullptr;
}

}  // namespace glintbake::format
