// SPDX-License-Identifier: Apache-2.0
// The wang-tiles records, their checks and the implicit grid rule (see kinds/wang.h).
#include <glintbake/format/kinds/wang.h>

#include <cmath>
#include <cstring>

namespace glintbake::format {

double wangCoverRadius(double sigma) {
  const double sigma_h = 1.5 / std::sqrt(12.0);
  return 4.0 * std::sqrt(sigma_h * sigma_h + sigma * sigma);
}

double wangMaxSigma(uint32_t tile_size) {
  const double sigma_h = 1.5 / std::sqrt(12.0);
  const double r = double(tile_size) / 4.0;
  return std::sqrt(r * r - sigma_h * sigma_h);
}

uint64_t wangVertexHash(int64_t x, int64_t y, uint64_t seed) {
  uint64_t k = uint64_t(uint32_t(x)) | (uint64_t(uint32_t(y)) << 32);
  k += seed * 0x9E3779B97F4A7C15ull;
  k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
  k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
  return k ^ (k >> 31);
}

void wangCellEdges(int64_t i, int64_t j, uint32_t colors, uint64_t seed, uint8_t edges[4]) {
  const auto right = [&](int64_t x, int64_t y) { return uint8_t((wangVertexHash(x, y, seed) >> 32) % colors); };
  const auto below = [&](int64_t x, int64_t y) {
    return uint8_t((wangVertexHash(x, y, seed) & 0xffffffffull) % colors);
  };
  edges[kWangNorth] = right(i, j);
  edges[kWangSouth] = right(i, j + 1);
  edges[kWangWest] = below(i, j);
  edges[kWangEast] = below(i + 1, j);
}

const char* checkWangRecord(const WangRecord& r) {
  if (r.magic != WangRecord().magic) return "wang record: bad magic";
  if (r.version != 1) return "wang record: unsupported version";
  if (r.colors < kMinWangColors || r.colors > kMaxWangColors) return "wang record: colors out of range";
  if (r.tile_count != r.colors * r.colors * r.colors * r.colors) return "wang record: tile_count is not colors^4";
  if (r.tile_size < kMinWangTileSize || r.tile_size > kMaxWangTileSize) return "wang record: tile_size out of range";
  if (r.margin < 1 || r.margin > 2 * r.tile_size) return "wang record: margin out of range";
  if (r.ndf_res < 2 || r.ndf_res > 4096) return "wang record: ndf_res out of range";
  if (r.rate < 1 || r.rate > 16) return "wang record: rate out of range";
  if (!(std::isfinite(r.sigma_r) && r.sigma_r > 0.0 && r.sigma_r <= 1.0)) return "wang record: sigma_r out of range";
  if (!(std::isfinite(r.max_sigma) && r.max_sigma > 0.0 && r.max_sigma <= wangMaxSigma(r.tile_size) * (1 + 1e-12)))
    return "wang record: max_sigma out of range";
  if (!(std::isfinite(r.flakes_up_to) && r.flakes_up_to >= 0.0 && r.flakes_up_to <= r.max_sigma))
    return "wang record: flakes_up_to out of range";
  if (!(std::isfinite(r.pyramid_from) && r.pyramid_from >= r.flakes_up_to))
    return "wang record: pyramid_from out of range";
  // The exact path answers up to pyramid_from; its window (6 sqrt(sigma_h^2 + sigma^2), 1.5 cover
  // radii) must stay within one tile so that a footprint meets at most 3 x 3 tiles on that path too.
  if (r.pyramid_from > r.max_sigma || 1.5 * wangCoverRadius(r.pyramid_from) > double(r.tile_size))
    return "wang record: pyramid_from too large for the tile size";
  return nullptr;
}

size_t wangEdgesBytes(const WangRecord& r) { return size_t(r.tile_count) * 4 + size_t(r.tile_count) * 4; }

size_t wangTexelsBytes(const WangRecord& r) {
  return size_t(r.tile_count) * size_t(r.tile_size) * size_t(r.tile_size) * 2 * sizeof(float);
}

const char* checkWangEdges(const WangRecord& r, const void* data, size_t size) {
  if (!data || size != wangEdgesBytes(r)) return "wang edges: size does not match the record";
  const uint8_t* bytes = static_cast<const uint8_t*>(data);
  const uint8_t* colours = bytes + size_t(r.tile_count) * 4;
  for (uint32_t t = 0; t < r.tile_count; ++t) {
    for (int e = 0; e < 4; ++e) {
      if (colours[t * 4 + e] >= r.colors) return "wang edges: colour out of range";
    }
  }
  for (uint32_t code = 0; code < r.tile_count; ++code) {
    uint32_t tile = 0;
    std::memcpy(&tile, bytes + size_t(code) * 4, 4);
    if (tile >= r.tile_count) return "wang edges: map entry out of range";
    if (wangTileCode(r.colors, colours + size_t(tile) * 4) != code)
      return "wang edges: map entry names a tile of another edge code";
  }
  return nullptr;
}

}  // namespace glintbake::format
