// SPDX-License-Identifier: Apache-2.0
// Byte offsets of the on-disk structures (formats/SPEC.md, "Header" and "Section index"), and
// little-endian load/store helpers. Private to the container library.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace glintbake::format::layout {

constexpr uint8_t kMagic[8] = {0xAB, 'G', 'B', 'K', 0x0D, 0x0A, 0x1A, 0x0A};

// File header (kHeaderSize = 128 bytes).
constexpr size_t kOffMagic = 0;            // u8[8]
constexpr size_t kOffVersionMajor = 8;     // u16
constexpr size_t kOffVersionMinor = 10;    // u16
constexpr size_t kOffAssetKind = 12;       // u32
constexpr size_t kOffHeaderSize = 16;      // u32, 128
constexpr size_t kOffFlags = 20;           // u32, 0
constexpr size_t kOffSectionCount = 24;    // u32
constexpr size_t kOffHeaderReserved = 28;  // u32, 0
constexpr size_t kOffIndexOffset = 32;     // u64
constexpr size_t kOffIndexSize = 40;       // u64
constexpr size_t kOffFileSize = 48;        // u64
constexpr size_t kOffFileChecksum = 56;    // u64, XXH3-64 of bytes [128, file_size)
constexpr size_t kOffIndexChecksum = 64;   // u64, XXH3-64 of the index bytes
constexpr size_t kOffHeaderChecksum = 72;  // u64, XXH3-64 of the header with this field zeroed
constexpr size_t kOffHeaderPadding = 80;   // zero up to 128

// Section index entry (kIndexEntrySize = 64 bytes).
constexpr size_t kEntType = 0;         // u32
constexpr size_t kEntCodec = 4;        // u32
constexpr size_t kEntKey = 8;          // u64
constexpr size_t kEntOffset = 16;      // u64
constexpr size_t kEntStoredSize = 24;  // u64
constexpr size_t kEntRawSize = 32;     // u64
constexpr size_t kEntChecksum = 40;    // u64
constexpr size_t kEntFlags = 48;       // u32
constexpr size_t kEntReserved = 52;    // u32
constexpr size_t kEntPadding = 56;     // zero up to 64

// ImageSectionHeader (32 bytes) at the start of image-like section payloads.
constexpr uint32_t kImageMagic = 0x474D4947;  // "GIMG" read as little-endian u32
constexpr size_t kImageHeaderSize = 32;

inline uint16_t load16(const uint8_t* p) { return uint16_t(p[0] | (p[1] << 8)); }
inline uint32_t load32(const uint8_t* p) {
  return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}
inline uint64_t load64(const uint8_t* p) { return uint64_t(load32(p)) | (uint64_t(load32(p + 4)) << 32); }

inline void store16(uint8_t* p, uint16_t v) {
  p[0] = uint8_t(v);
  p[1] = uint8_t(v >> 8);
}
inline void store32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
inline void store64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = uint8_t(v >> (8 * i));
}

// Rounds up to the section alignment (callers check for overflow where the value is untrusted).
inline uint64_t alignUp(uint64_t v, uint64_t alignment) { return (v + alignment - 1) / alignment * alignment; }

}  // namespace glintbake::format::layout
