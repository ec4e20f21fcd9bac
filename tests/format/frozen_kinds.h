// SPDX-License-Identifier: Apache-2.0
// The exact content of the frozen version-1.0 containers of every asset kind (one file per kind,
// formats/SPEC.md section 10): their records are spelt out here byte by byte from the SPEC's
// tables (offsets and widths), not from the structs, so a change of a record's layout fails the
// test. Shared by the generator (generate_frozen.cpp, run once) and by frozen_kinds_test.cpp.
#pragma once

#include <glintbake/format/container.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace glintbake::format::frozen {

// Little-endian record bytes, field by field at the SPEC's offsets.
class Bytes {
 public:
  explicit Bytes(size_t size) : bytes_(size, 0) {}
  Bytes& u16(size_t at, uint16_t v) { return put(at, &v, 2); }
  Bytes& u32(size_t at, uint32_t v) { return put(at, &v, 4); }
  Bytes& f32(size_t at, float v) { return put(at, &v, 4); }
  Bytes& f64(size_t at, double v) { return put(at, &v, 8); }
  Bytes& u64(size_t at, uint64_t v) { return put(at, &v, 8); }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  Bytes& put(size_t at, const void* v, size_t n) {
    // The file is little-endian; so are the hosts this project builds on.
    if (at + n <= bytes_.size()) std::memcpy(bytes_.data() + at, v, n);
    return *this;
  }
  std::vector<uint8_t> bytes_;
};

inline std::string kindMetadata(const char* kind, const char* tool) {
  return std::string(R"({"schema":"glintbake.container-metadata/1","asset_kind":")") + kind +
         R"(","generator":{"tool":")" + tool + R"(","version":"0.1.0"},"parameters":{"frozen":true},)" +
         R"("inputs":[{"name":"frozen.png","hash":"xxh3-128:00112233445566778899aabbccddeeff"}]})";
}

// An image section (SPEC 3.1) whose value (x, y, c, l) is value(x, y, c, l).
template <typename Value>
std::vector<uint8_t> imageSection(uint32_t w, uint32_t h, uint32_t c, uint32_t layers, Value value) {
  Bytes b(32 + 4 * size_t(w) * h * c * layers);
  b.u32(0, 0x474D4947).u32(4, w).u32(8, h).u32(12, c).u32(16, layers);
  size_t at = 32;
  for (uint32_t l = 0; l < layers; ++l)
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x)
        for (uint32_t ch = 0; ch < c; ++ch, at += 4) b.f32(at, value(x, y, ch, l));
  return b.bytes();
}

// --- ndf-pyramid (SPEC 10.1): an 8 x 8 repeating map, R = 4, two levels (2 x 2 and 1 x 1 centres,
// one region each). ---------------------------------------------------------------------------

constexpr uint32_t kPyramidRes = 4;

// ndf-level record of level 0 or 1 (112 bytes).
inline std::vector<uint8_t> pyramidLevel(uint32_t level) {
  const uint32_t grid = level == 0 ? 2 : 1;
  const double stride = level == 0 ? 4.0 : 8.0;
  Bytes b(112);
  b.u32(0, 0x4C444E47).u32(4, 1).u32(8, level).u32(12, kPyramidRes);
  b.u32(16, grid).u32(20, grid).u32(24, 2).u32(28, 1).u32(32, 1);
  b.u32(36, 0).u32(40, 8).u32(44, 8).u32(48, 1).u32(52, 0);
  b.f64(56, stride).f64(64, stride).f64(72, stride / 2).f64(80, stride / 2);
  b.f64(88, level == 0 ? 2.0 : 4.0).f64(96, 0.005).f64(104, 0.0);
  return b.bytes();
}

// Bin (i, j) of the image of centre k of a level: exact in float32, non-negative.
inline float pyramidBin(uint32_t level, uint32_t k, uint32_t i, uint32_t j) {
  return 0.0625f * float(1 + i + 2 * j + 4 * k + 16 * level);
}

inline std::vector<uint8_t> pyramidChunk(uint32_t level) {
  const uint32_t layers = level == 0 ? 4 : 1;
  return imageSection(kPyramidRes, kPyramidRes, 1, layers,
                      [level](uint32_t x, uint32_t y, uint32_t, uint32_t l) { return pyramidBin(level, l, x, y); });
}

// --- tensor-ndf (SPEC 10.4): R = 4 in 2 x 2 blocks of B = 2, one level of one centre, one group
// of rank 1 holding two blocks, float16 factors, non-negative. -------------------------------

inline std::vector<uint8_t> tensorLevel() {
  Bytes b(112);
  b.u32(0, 0x4C444E47).u32(4, 1).u32(8, 0).u32(12, 4);
  b.u32(16, 1).u32(20, 1).u32(24, 1).u32(28, 1).u32(32, 1);
  b.u32(36, 1).u32(40, 16).u32(44, 16).u32(48, 1);
  b.f64(56, 16.0).f64(64, 16.0).f64(72, 8.0).f64(80, 8.0).f64(88, 8.0).f64(96, 0.005);
  return b.bytes();
}

inline std::vector<uint8_t> tensorInfo() {
  Bytes b(64);
  b.u32(0, 0x494E5447).u32(4, 1).u32(8, 4).u32(12, 2).u32(16, 2).u32(20, 1).u32(24, 1).u32(28, 1);
  b.u32(32, 1).u32(36, 1).f64(40, 1e-6);
  return b.bytes();
}

// Blocks 0 and 3 are rows 0 and 1 of group 0; blocks 1 and 2 were dropped.
inline std::vector<uint8_t> tensorIndex() {
  Bytes b(4 * 8);
  b.u32(0, 0).u32(4, 0).u32(8, 0xFFFFFFFFu).u32(12, 0).u32(16, 0xFFFFFFFFu).u32(20, 0).u32(24, 0).u32(28, 1);
  return b.bytes();
}

// Factors A = (1, 0.5), B = (0.25, 1), C = (2, 0.5) as binary16, then the float32 prefix sums.
constexpr float kTensorA[2] = {1.0f, 0.5f}, kTensorB[2] = {0.25f, 1.0f}, kTensorC[2] = {2.0f, 0.5f};

inline std::vector<uint8_t> tensorGroup() {
  Bytes b(32 + 2 * 6 + 4 * 6);
  b.u32(0, 0x474E5447).u32(4, 2).u32(8, 1).u32(12, 2).u32(16, 0).u32(20, 0).u32(24, 1).u32(28, 0);
  // binary16 of 1, 0.5 | 0.25, 1 | 2, 0.5
  b.u16(32, 0x3C00).u16(34, 0x3800).u16(36, 0x3400).u16(38, 0x3C00).u16(40, 0x4000).u16(42, 0x3800);
  b.f32(44, 0.0f).f32(48, 1.0f).f32(52, 1.5f);    // A prefix
  b.f32(56, 0.0f).f32(60, 0.25f).f32(64, 1.25f);  // B prefix
  return b.bytes();
}

// --- ltc-table (SPEC 10.2): N = 2, 4 channels. ---------------------------------------------------

inline float ltcValue(uint64_t key, uint32_t a, uint32_t t, uint32_t c) {
  return float(key) * 8.0f + float(a) + 2.0f * float(t) + 0.25f * float(c) + 0.5f;
}

inline std::vector<uint8_t> ltcSection(uint64_t key) {
  return imageSection(2, 2, 4, 1,
                      [key](uint32_t x, uint32_t y, uint32_t c, uint32_t) { return ltcValue(key, x, y, c); });
}

// --- roughness (SPEC 10.3): a 3 x 2 map, mips 3 x 2, 2 x 1, 1 x 1. ------------------------------

constexpr uint32_t kRoughnessW[3] = {3, 2, 1}, kRoughnessH[3] = {2, 1, 1};

inline float roughnessValue(uint32_t level, uint32_t x, uint32_t y) {
  return 0.125f * float(1 + x + 3 * y) + 0.0625f * float(level);
}

inline std::vector<uint8_t> roughnessMip(uint32_t level) {
  return imageSection(kRoughnessW[level], kRoughnessH[level], 1, 1,
                      [level](uint32_t x, uint32_t y, uint32_t, uint32_t) { return roughnessValue(level, x, y); });
}

// --- glitter (SPEC 10.6): 1000 Beckmann facets, alpha 0.3, a 16 x 16 map, R = 8, an 8-entry
// integral table (root 0 with four tabulated children). ------------------------------------------

inline std::vector<uint8_t> glitterRecord() {
  Bytes b(80);
  b.u32(0, 0x544C4747).u32(4, 1).u32(8, 0).u32(12, 20);
  b.u32(16, 1000).u32(20, 0);  // particles (u64)
  b.u32(24, 5).u32(28, 0);     // seed (u64)
  b.f64(32, 0.3).f64(40, 0.05);
  b.u32(48, 16).u32(52, 16).u32(56, 8).u32(60, 8);
  b.f64(64, 0.01).f64(72, 0.01);
  return b.bytes();
}

constexpr double kGlitterIntegrals[8] = {0.25, 0.25, 0.25, 0.25, 0.1, 0.05, 0.05, 0.05};

inline std::vector<uint8_t> glitterIntegrals() {
  Bytes b(8 * 16);
  for (size_t i = 0; i < 8; ++i) b.f64(16 * i, kGlitterIntegrals[i]);
  b.u32(8, 4);  // entry 0: first child 4
  return b.bytes();
}

// --- tiny-example (SPEC 10.8): a 4 x 4 example, R = 4, tiled with the identity, sigma_r 0.05;
// levels of 2 x 2 tiles and one tile. -----------------------------------------------------------

inline std::vector<uint8_t> tinyRecord() {
  Bytes b(168);
  b.u32(0, 0x594E5447).u32(4, 1).u32(8, 4).u32(12, 2).u32(16, 4).u32(20, 0).u32(24, 0).u32(28, 0);
  b.f64(32, 0.05);
  b.f64(40, 1.0).f64(48, 0.0).f64(56, 0.0).f64(64, 1.0);  // matrix
  b.f64(136, 1.0).f64(144, 1.0);                          // scale_range
  return b.bytes();
}

inline float tinyTexel(uint32_t x, uint32_t y, uint32_t c) {
  return 0.0625f * float(x) - 0.125f * float(y) + 0.25f * float(c);
}

inline std::vector<uint8_t> tinyTexels() {
  Bytes b(4 * 4 * 8);
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x)
      for (uint32_t c = 0; c < 2; ++c) b.f32(((y * 4 + x) * 2 + c) * 4, tinyTexel(x, y, c));
  return b.bytes();
}

// Bin (x, y) of tile `tile` of `level`; the corner bins (centres outside the unit disk) hold 0.
inline float tinyValue(uint32_t level, uint32_t tile, uint32_t x, uint32_t y) {
  if ((x == 0 || x == 3) && (y == 0 || y == 3)) return 0.0f;
  return 0.125f * float(1 + x + 4 * y) + 0.5f * float(level) + 0.0625f * float(tile);
}

inline std::vector<uint8_t> tinyLevel(uint32_t level) {
  return imageSection(4, 4, 1, level == 0 ? 4 : 1, [level](uint32_t x, uint32_t y, uint32_t, uint32_t layer) {
    return tinyValue(level, layer, x, y);
  });
}

// --- tiny-example, record version 2 (SPEC 10.8): the same example, texels and levels, stochastic
// with flags layout | overlap: seed 7, density 0.5, cell 2 texels, occupancy 1, rotations 0-180
// degrees, scale 1, and a 2 x 1 layout of two channels (presence 1 and 0, rotation 0.5 and 0). --

inline std::vector<uint8_t> tinyRecordV2() {
  Bytes b(168);
  b.u32(0, 0x594E5447).u32(4, 2).u32(8, 4).u32(12, 2).u32(16, 4).u32(20, 1).u32(24, 3).u32(28, 0);
  b.f64(32, 0.05);
  b.f64(40, 1.0).f64(48, 0.0).f64(56, 0.0).f64(64, 1.0);  // matrix
  b.u64(88, 7).f64(96, 0.5).f64(104, 2.0).f64(112, 1.0);  // seed, density, cell_size, occupancy
  b.f64(120, 0.0).f64(128, 180.0);                        // rotate_range
  b.f64(136, 1.0).f64(144, 1.0);                          // scale_range
  return b.bytes();
}

// --- tiny-example, record version 2 with flag half (SPEC 10.8): the tiled example above with its
// levels as binary16 (section 116; every value a multiple of 1/16, exact in binary16). -------------

inline std::vector<uint8_t> tinyRecordHalf() {
  std::vector<uint8_t> out = tinyRecord();
  const uint32_t version = 2, flags = 4;
  std::memcpy(out.data() + 4, &version, 4);
  std::memcpy(out.data() + 24, &flags, 4);
  return out;
}

// binary16 bits of a non-negative value exact in binary16 (a normal number or 0).
inline uint16_t tinyHalfBits(float v) {
  if (v == 0.0f) return 0;
  int e = 0;
  const float m = std::frexp(v, &e);  // v = m 2^e, m in [0.5, 1)
  return uint16_t(((e - 1 + 15) << 10) | uint32_t(std::lround((2.0f * m - 1.0f) * 1024.0f)));
}

inline std::vector<uint8_t> tinyLevelHalf(uint32_t level) {
  const uint32_t layers = level == 0 ? 4 : 1;
  Bytes b(32 + 2 * 16 * layers);
  b.u32(0, 0x484D4947).u32(4, 4).u32(8, 4).u32(12, 1).u32(16, layers);
  for (uint32_t l = 0; l < layers; ++l)
    for (uint32_t y = 0; y < 4; ++y)
      for (uint32_t x = 0; x < 4; ++x) b.u16(32 + 2 * ((l * 4 + y) * 4 + x), tinyHalfBits(tinyValue(level, l, x, y)));
  return b.bytes();
}

inline std::vector<uint8_t> tinyLayoutV2() {
  Bytes b(32 + 2 * 2 * 4);  // image header (SPEC 3.1), then (presence, rotation) of cells 0 and 1
  b.u32(0, 0x474D4947).u32(4, 2).u32(8, 1).u32(12, 2).u32(16, 1);
  b.f32(32, 1.0f).f32(36, 0.5f).f32(40, 0.0f).f32(44, 0.0f);
  return b.bytes();
}

}  // namespace glintbake::format::frozen

namespace glintbake::format::frozen {

// --- wang-tiles (SPEC 10.7): C = 2 (16 tiles) of 8 x 8 texels, margin 8, grid seed 3, R = 4; every
// tile's NDF asset is the same embedded ndf-pyramid of one level (one centre, sigma 1, over the
// 24 x 24 clamped extended square, a uniform image). ------------------------------------------------

constexpr uint32_t kWangTile = 8, kWangMargin = 8, kWangRes = 4, kWangTiles = 16;

inline std::vector<uint8_t> wangRecord() {
  Bytes b(72);
  b.u32(0, 0x474E5747).u32(4, 1).u32(8, 2).u32(12, kWangTiles).u32(16, kWangTile).u32(20, kWangMargin);
  b.u32(24, 3).u32(28, 0);  // seed (u64)
  b.u32(32, kWangRes).u32(36, 1);
  b.f64(40, 0.005).f64(48, 0.5).f64(56, 1.0).f64(64, 1.5);
  return b.bytes();
}

// Entry `code` names tile `code`; tile t's colours are the digits of t in base 2 (N E S W).
inline std::vector<uint8_t> wangEdges() {
  Bytes b(kWangTiles * 8);
  for (uint32_t t = 0; t < kWangTiles; ++t) b.u32(4 * t, t);
  std::vector<uint8_t> bytes = b.bytes();
  for (uint32_t t = 0; t < kWangTiles; ++t) {
    for (uint32_t e = 0; e < 4; ++e) bytes[4 * kWangTiles + 4 * t + e] = uint8_t((t >> (3 - e)) & 1u);
  }
  return bytes;
}

// (n_x, n_y) of texel (x, y) of tile t: small multiples of 1/64, exact in float32.
inline float wangNormal(uint32_t t, uint32_t x, uint32_t y, uint32_t c) {
  return c == 0 ? float(int((t + x) % 5) - 2) / 64.0f : float(int((t + 2 * y) % 3) - 1) / 64.0f;
}

inline std::vector<uint8_t> wangTexels() {
  Bytes b(size_t(kWangTiles) * kWangTile * kWangTile * 8);
  size_t at = 0;
  for (uint32_t t = 0; t < kWangTiles; ++t)
    for (uint32_t y = 0; y < kWangTile; ++y)
      for (uint32_t x = 0; x < kWangTile; ++x)
        for (uint32_t c = 0; c < 2; ++c, at += 4) b.f32(at, wangNormal(t, x, y, c));
  return b.bytes();
}

// The embedded tile asset's level record (SPEC 10.1: 112 bytes) and its one image.
inline std::vector<uint8_t> wangTileLevel() {
  const uint32_t side = kWangTile + 2 * kWangMargin;
  Bytes b(112);
  b.u32(0, 0x4C444E47).u32(4, 1).u32(8, 0).u32(12, kWangRes);
  b.u32(16, 1).u32(20, 1).u32(24, 1).u32(28, 1).u32(32, 1);
  b.u32(36, 1).u32(40, side).u32(44, side).u32(48, 1).u32(52, 0);
  b.f64(56, double(side)).f64(64, double(side)).f64(72, side / 2.0).f64(80, side / 2.0);
  b.f64(88, 1.0).f64(96, 0.005).f64(104, 0.0);
  return b.bytes();
}

inline std::vector<uint8_t> wangTileChunk() {
  return imageSection(kWangRes, kWangRes, 1, 1, [](uint32_t, uint32_t, uint32_t, uint32_t) { return 0.25f; });
}

// partial (SPEC 10.9): shard 0 of 2 of a test asset; it holds position 1, an image-typed raw
// section (key 7) of 8 bytes (two float32: 1, 2).
inline std::vector<uint8_t> shardSection() {
  Bytes b(40 + 8);
  b.u32(0, 0x53484753).u32(4, 0).u32(8, 256).u32(12, 0);
  b.u64(16, 7).u64(24, 8).u64(32, 8);
  b.f32(40, 1.0f).f32(44, 2.0f);
  return b.bytes();
}

// The merged asset's metadata text the partial carries (section 144).
inline std::vector<uint8_t> shardMetadata() {
  const std::string text = kindMetadata("test", "frozen");
  return std::vector<uint8_t>(text.begin(), text.end());
}

}  // namespace glintbake::format::frozen
