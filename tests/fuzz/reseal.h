// SPDX-License-Identifier: Apache-2.0
// Shared by the container fuzz targets: recomputes the index, file and header checksums
// (formats/SPEC.md 2.1) of mutated bytes, so that mutations reach the checks behind the checksums
// instead of stopping at a checksum mismatch.
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glintbake::fuzz {

inline uint64_t load64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

inline void store64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = uint8_t(v >> (8 * i));
}

inline std::vector<uint8_t> reseal(const uint8_t* data, size_t size) {
  using format::hash64;
  using format::kHeaderSize;
  std::vector<uint8_t> bytes(data, data + size);
  if (size < kHeaderSize) return bytes;
  uint8_t* h = bytes.data();
  const uint64_t index_offset = load64(h + 32), index_size = load64(h + 40);
  if (index_offset <= size && index_size <= size - index_offset) {
    store64(h + 64, hash64(h + index_offset, size_t(index_size)));
  }
  store64(h + 56, hash64(h + kHeaderSize, size - kHeaderSize));
  store64(h + 72, 0);
  store64(h + 72, hash64(h, kHeaderSize));
  return bytes;
}

}  // namespace glintbake::fuzz
