// SPDX-License-Identifier: Apache-2.0
// Records of ndf-pyramid assets (formats/SPEC.md section 10.1), written by ndfgen and by the
// tensor-ndf packer, read by the runtime and by the packer. Stored as the raw little-endian bytes
// of the structs.
//
//  - section 16 `ndf-level` (key = level): one NdfLevelRecord per level;
//  - section 17 `ndf-chunk` (key = level << 32 | region, region = ry * regions_x + rx): an image
//    section (SPEC 3.1) with width = height = R, channels = 1, layers = the region's centres in
//    row-major order within the region.
// tensor-ndf assets (kinds/tensor_ndf.h) store the same level records.
#pragma once

#include <glintbake/format/records.h>

#include <cstdint>

namespace glintbake::format {

// Level descriptor (112 bytes).
struct NdfLevelRecord {
  uint32_t magic = 0x4C444E47;  // "GNDL"
  uint32_t version = 1;
  uint32_t level = 0;
  uint32_t ndf_res = 0;      // R: bins per side of every image
  uint32_t grid_width = 0;   // footprint centres per row
  uint32_t grid_height = 0;  // footprint centres per column
  uint32_t region_size = 0;  // centres per side of a spatial region (chunk)
  uint32_t regions_x = 0;    // ceil(grid_width / region_size)
  uint32_t regions_y = 0;    // ceil(grid_height / region_size)
  uint32_t wrap = 0;         // 0 = repeat, 1 = clamp
  uint32_t map_width = 0;    // texels of the source map
  uint32_t map_height = 0;
  uint32_t rate = 1;  // flakes per texel side used to bake
  uint32_t reserved = 0;
  double stride_x = 0.0;  // texels between centres along x (= map_width / grid_width)
  double stride_y = 0.0;  // texels between centres along y (= map_height / grid_height)
  double origin_x = 0.0;  // position of centre (0, 0), texels (= stride / 2)
  double origin_y = 0.0;
  double sigma_texels = 0.0;  // footprint std of this level
  double sigma_r = 0.0;       // intrinsic roughness used to bake
  double reserved2 = 0.0;
};
static_assert(sizeof(NdfLevelRecord) == 112, "NdfLevelRecord is 112 bytes");

constexpr int kMaxNdfLevels = 32;               // most levels a pyramid may have
constexpr uint32_t kMaxNdfResolution = 4096;    // largest R
constexpr uint32_t kMaxNdfGridSide = 1u << 20;  // most centres per grid row or column

// Key of the ndf-chunk section of region `region` of level `level`.
constexpr uint64_t ndfChunkKey(uint32_t level, uint64_t region) { return (uint64_t(level) << 32) | region; }

// Checks one level record as every reader and writer must: magic and version, level == key,
// R in [2, kMaxNdfResolution], grid sides in [1, kMaxNdfGridSide], a region layout consistent with
// the grid, wrap 0 or 1, strides and sigma finite and positive, origins and sigma_r finite. With
// `below` (the record of level key - 1), also the same R and a larger sigma. Safe on untrusted
// records (pure function of the bytes).
RecordCheck checkNdfLevelRecord(const NdfLevelRecord& record, uint32_t key, const NdfLevelRecord* below);

}  // namespace glintbake::format
