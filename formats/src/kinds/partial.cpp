// SPDX-License-Identifier: Apache-2.0
// Checks of the partial kind's records (see kinds/partial.h).
#include <glintbake/format/kinds/partial.h>

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

}  // namespace glintbake::format
