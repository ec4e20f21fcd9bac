// SPDX-License-Identifier: Apache-2.0
// The wang-tiles asset kind (formats/SPEC.md 10.7): an edge-coloured Wang tile set (Cohen et al.
// 2003, "Wang Tiles for Image and Texture Generation") laid on an implicit, hashed grid covering the
// unbounded plane (the corner-hash variant of Lagae and Dutre 2005, "A Procedural Object
// Distribution Function", as used by Deng et al. 2022 section 5.5), with one NDF asset per tile.
// The records, their checks and the grid rule shared by the baker, the runtime and the validator.
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

constexpr uint32_t kMinWangColors = 2;
constexpr uint32_t kMaxWangColors = 4;
constexpr uint32_t kMinWangTileSize = 8;
constexpr uint32_t kMaxWangTileSize = 4096;

// Section kSectionWangInfo (key 0, exactly one), 72 bytes little-endian.
struct WangRecord {
  uint32_t magic = 0x474E5747;  // "GWNG"
  uint32_t version = 1;
  uint32_t colors = 2;      // C colours per edge, kMinWangColors..kMaxWangColors
  uint32_t tile_count = 0;  // C^4 (a complete set)
  uint32_t tile_size = 0;   // T: texels per tile side, kMinWangTileSize..kMaxWangTileSize
  uint32_t margin = 0;      // M: texels each tile's NDF asset extends beyond the tile on every side, >= 1
  uint64_t seed = 0;        // selects the grid's realisation (wangVertexHash)
  uint32_t ndf_res = 0;     // R of every tile's NDF images, 2..4096
  uint32_t rate = 1;        // flakes per texel side of the exact path, 1..16
  double sigma_r = 0.0;     // intrinsic roughness of the flakes, (0, 1]
  double flakes_up_to = 0;  // footprints with sigma <= this are answered by the flakes alone, >= 0
  double pyramid_from = 0;  // ... from this on by the tiles' NDF assets alone (>= flakes_up_to)
  double max_sigma = 0;     // the largest footprint answered; larger ones are clamped to it, > 0
};
static_assert(sizeof(WangRecord) == 72, "WangRecord is 72 bytes");

// The footprint radius (texels) within which a tile counts for a footprint of std sigma: the
// splat's truncation, 4 sqrt(sigma_h^2 + sigma^2) with sigma_h = 1.5 / sqrt(12) of a rate-1 flake.
double wangCoverRadius(double sigma);
// The largest sigma whose cover radius is at most T: a footprint then meets at most 3 x 3 tiles.
double wangMaxSigma(uint32_t tile_size);

// Edge colours of a tile, in the order of the tile code: code = ((N C + E) C + S) C + W.
enum WangEdge : int { kWangNorth = 0, kWangEast = 1, kWangSouth = 2, kWangWest = 3 };
constexpr uint32_t wangTileCode(uint32_t colors, const uint8_t edges[4]) {
  return ((uint32_t(edges[kWangNorth]) * colors + edges[kWangEast]) * colors + edges[kWangSouth]) * colors +
         edges[kWangWest];
}

// The hash of grid vertex (x, y) (SPEC.md 10.7): x and y as 32-bit two's complement, packed into
// k = x | y << 32, h = mix(k + seed * 0x9E3779B97F4A7C15) with the 64-bit finaliser of SplitMix64.
uint64_t wangVertexHash(int64_t x, int64_t y, uint64_t seed);

// The edge colours of grid cell (i, j) (the tile spanning [i T, (i + 1) T) x [j T, (j + 1) T)
// texels, y down): vertex (x, y) owns the horizontal edge to its right (colour (h >> 32) mod C)
// and the vertical edge below it (colour (h & 0xffffffff) mod C), so N = right edge of (i, j),
// S = right edge of (i, j + 1), W = edge below (i, j), E = edge below (i + 1, j). Neighbouring
// cells share their edge colours by construction.
void wangCellEdges(int64_t i, int64_t j, uint32_t colors, uint64_t seed, uint8_t edges[4]);

// Checks a record against SPEC.md 10.7 (null when valid, otherwise a short message naming the
// first offending field). Safe on untrusted input.
const char* checkWangRecord(const WangRecord& record);

// Bytes of the kSectionWangEdges section of a record: the edge-code-to-tile map (tile_count
// uint32) followed by the edge colours of every tile (4 uint8 per tile, N E S W).
size_t wangEdgesBytes(const WangRecord& record);
// Bytes of the kSectionWangTexels section: tile_count * T * T * 2 float32, tile after tile, each
// tile row-major (row 0 at the top), (n_x, n_y) per texel.
size_t wangTexelsBytes(const WangRecord& record);

// Checks the edges section (size bytes) of a checked record: the size, every colour below C, every
// map entry a tile whose colours give that code. Null when valid. Safe on untrusted input.
const char* checkWangEdges(const WangRecord& record, const void* data, size_t size);

}  // namespace glintbake::format
