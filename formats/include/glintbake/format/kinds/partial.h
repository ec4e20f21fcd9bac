// SPDX-License-Identifier: Apache-2.0
// The partial kind (formats/SPEC.md 10.9): one shard of a sharded bake. A tool run with
// --shard I/N bakes a deterministic share of an asset's sections into a partial container;
// `glintinfo merge` puts the N partials back together into the asset, byte for byte the file one
// machine would have written. A partial is never an asset: the runtime refuses to open it.
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

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

}  // namespace glintbake::format
