// SPDX-License-Identifier: Apache-2.0
// The flakes section of NDF assets (formats/SPEC.md 10.5): the normal map a pyramid was baked from,
// stored so that the runtime evaluates small footprints exactly from its flakes (Yan et al. 2016)
// instead of from the finest pyramid level.
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

// Header of the flakes section (kSectionFlakes, key 0, at most one per ndf-pyramid or tensor-ndf
// asset), 64 bytes little-endian, followed by map_width * map_height pairs
// of float32 (n_x, n_y), row-major, row 0 at the top (SPEC.md section 9 coordinates), and from
// version 3 by a FlakesTrailer.
struct FlakesRecord {
  uint32_t magic = 0x4B4C4647;  // "GFLK"
  uint32_t version = 3;         // 1: no clustered path (lobes_per_tile and lobes_up_to are ignored);
                                // 3: a FlakesTrailer follows the normals
  uint32_t map_width = 0;       // texels
  uint32_t map_height = 0;      // texels
  uint32_t wrap = 0;            // 0 repeat, 1 clamp: how the map continues beyond its edges
  uint32_t rate = 1;            // flakes per texel side (1..16)
  uint32_t precision = 0;       // 0: float32 normals (the only value)
  uint32_t lobes_per_tile = 0;  // version 2: lobes per tile of the clustered path, 1..16; 0: none
  double sigma_r = 0.0;         // intrinsic roughness, s-plane std of every flake (0, 1]
  double flakes_up_to = 0.0;    // footprints with sigma <= this (texels) are answered by the flakes alone
  double pyramid_from = 0.0;    // footprints with sigma >= this are answered by the pyramid alone
  // Version 2 with lobes_per_tile > 0: the clustered lobes answer alone from kLobesBand x
  // flakes_up_to to this, and hand over to the pyramid from here to pyramid_from. Every band
  // blends its two paths linearly in log(sigma).
  double lobes_up_to = 0.0;
};
static_assert(sizeof(FlakesRecord) == 64, "FlakesRecord is 64 bytes");

// Width of the band from the flakes to the clustered lobes: the lobes answer alone from
// kLobesBand x flakes_up_to (half an octave).
constexpr double kLobesBand = 1.4142135623730951;
constexpr uint32_t kMaxLobesPerTile = 16;

// Version 3 appends 8 bytes after the normals: the largest tile side of the clustered path's cut,
// as a fraction of the footprint's std, that answers near a footprint's centre, in thousandths.
// Writers lower it from the default where the map's tiles hold more distinct normals than a tile
// keeps lobes (SPEC.md 10.5); earlier versions are read with the default. As float32 both words
// are finite (zero or subnormal), as every float of the section after the record is.
struct FlakesTrailer {
  uint32_t tile_ratio_milli = 350;  // kMinFlakesTileRatioMilli..kMaxFlakesTileRatioMilli
  uint32_t reserved = 0;            // 0
};
static_assert(sizeof(FlakesTrailer) == 8, "FlakesTrailer is 8 bytes");
constexpr uint32_t kDefaultFlakesTileRatioMilli = 350;
constexpr uint32_t kMinFlakesTileRatioMilli = 62;
constexpr uint32_t kMaxFlakesTileRatioMilli = 1000;

// Checks a version-3 trailer (null when valid, else a short message).
const char* checkFlakesTrailer(const FlakesTrailer& trailer);

// The tile ratio (thousandths) of a section whose record passed checkFlakesRecord: its trailer's
// (version 3), else the default. `section` holds the section's raw_size bytes. Returns false for a
// version-3 trailer that fails checkFlakesTrailer.
bool flakesTileRatio(const FlakesRecord& record, const uint8_t* section, uint64_t raw_size, uint32_t* milli);

// Whether a (checked) record has a clustered path.
inline bool hasLobes(const FlakesRecord& r) { return r.version >= 2 && r.lobes_per_tile > 0; }

// Limits a reader accepts (checked before any allocation).
constexpr uint32_t kMaxFlakesMapSide = 1u << 16;
constexpr uint32_t kMaxFlakesRate = 16;
constexpr uint64_t kMaxFlakesCount = uint64_t(1) << 30;  // map texels x rate^2

// Bytes of a flakes section holding `record` (header and normals), or 0 when the record's sizes
// are out of range.
uint64_t flakesSectionSize(const FlakesRecord& record);

// Checks every field of a flakes record against SPEC.md 10.5 and the section's raw size: the one
// check used by every reader and writer. Returns null when valid, otherwise a short message
// naming the first offending field. Safe on untrusted input.
const char* checkFlakesRecord(const FlakesRecord& record, uint64_t section_raw_size);

}  // namespace glintbake::format
