// SPDX-License-Identifier: Apache-2.0
// The tiny-example asset kind (formats/SPEC.md 10.8): one small normal-map example with its
// multi-scale tile NDFs, placed procedurally over the unbounded plane (Xing et al., "Tiny
// example-based procedural microstructures"). The records, their checks and the placement rules
// shared by the baker, the runtime, the validator and the tests.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/kinds.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

enum class TinyExampleType : uint32_t {
  kTiled = 0,       // copies of the example tile the plane, one transform for all
  kStochastic = 1,  // at most one example per cell of a square grid, each with its own transform
};
const char* tinyExampleTypeString(TinyExampleType type);  // "tiled", "stochastic"; "unknown" otherwise

// Record flags (version 2; a version 1 record has none).
constexpr uint32_t kTinyFlagLayout = 1u;   // stochastic: section kSectionTinyExampleLayout holds a layout image
constexpr uint32_t kTinyFlagOverlap = 2u;  // stochastic: examples may overlap; the nearest centre owns a point
// Either type: the tile images are stored as binary16 in sections kSectionTinyExampleLevelHalf
// (instead of float32 in kSectionTinyExampleLevel).
constexpr uint32_t kTinyFlagHalf = 4u;
// Magic of the 32-byte header of a binary16 level section ("GIMH"; otherwise the image header of
// SPEC.md 3.1, values 2 bytes each).
constexpr uint32_t kTinyHalfImageMagic = 0x484D4947;
constexpr float kTinyHalfMax = 65504.0f;  // the largest finite binary16

// Section kSectionTinyExampleInfo (key 0, exactly one), 168 bytes little-endian.
struct TinyExampleRecord {
  uint32_t magic = 0x594E5447;  // "GTNY"
  uint32_t version = 1;         // 1, or 2 when flags are set
  uint32_t example_size = 0;    // n: texels per side of the example, a power of two in [4, 256]
  uint32_t levels = 0;          // log2(n): level l holds (n / 2^(l+1))^2 tiles of 2^(l+1) texels per side
  uint32_t ndf_res = 0;         // R: bins per side of every tile NDF image, 2..1024
  uint32_t type = 0;            // TinyExampleType
  uint32_t flags = 0;           // version 1: 0; version 2: kTinyFlag* bits
  uint32_t reserved = 0;
  double sigma_r = 0.0;  // intrinsic roughness of the texels' lobes, (0, 1]
  // The 2x2 part of the example transform, row-major {m00, m01, m10, m11}, acting on positions
  // (texels, y down): tiled: the one transform; stochastic: the part every example shares (mirror),
  // applied after its own rotation, scale and shear. |det| in [kMinTinyDet, kMaxTinyDet].
  double matrix[4] = {1.0, 0.0, 0.0, 1.0};
  double translate[2] = {0.0, 0.0};  // tiled: where the example's corner (0, 0) lands (texels)
  // Stochastic layout (ignored by the tiled type, 0 there).
  uint64_t seed = 0;
  double density = 0.0;                 // the covered fraction the layout was made for, (0, 1]
  double cell_size = 0.0;               // L: side of the grid cells (texels), each holds at most one example
  double occupancy = 0.0;               // probability that a cell holds an example, (0, 1]
  double rotate_range[2] = {0.0, 0.0};  // degrees, min <= max, |.| <= 3600
  double scale_range[2] = {1.0, 1.0};   // min <= max, both in [kMinTinyScale, kMaxTinyScale]
  double shear[2] = {0.0, 0.0};         // (hx, hy), |.| <= kMaxTinyShear, hx hy != 1
};
static_assert(sizeof(TinyExampleRecord) == 168, "TinyExampleRecord is 168 bytes");

constexpr uint32_t kMinTinyExampleSize = 4;
constexpr uint32_t kMaxTinyExampleSize = 256;
constexpr uint32_t kMaxTinyNdfRes = 1024;
constexpr double kMinTinyScale = 0.125;
constexpr double kMaxTinyScale = 8.0;
constexpr double kMaxTinyShear = 2.0;
constexpr double kMinTinyDet = 1.0 / 64.0;
constexpr double kMaxTinyDet = 64.0;
constexpr uint32_t kMaxTinyLayoutSide = 1024;  // cells per side of a layout image
constexpr uint32_t kMaxTinyLayoutChannels = 3;
// Overlapping layouts: an example reaches at most this many cells beyond its own (cell_size >=
// tinyMinCellSize / (2 kMaxTinyOverlapReach)), and their covered fraction is measured on a grid of
// kTinyCoverageSamples^2 points over kTinyCoverageCells^2 cells from the origin.
constexpr int kMaxTinyOverlapReach = 2;
constexpr int kTinyCoverageCells = 64;
constexpr int kTinyCoverageSamples = 256;

// A stochastic layout image (section kSectionTinyExampleLayout: an image section of width x height
// cells, `channels` floats each, one layer), repeating over the plane: layout cell (i, j) reads pixel
// (i mod width, j mod height), row 0 at the top (cells j = 0, y down). Every value lies in [0, 1]:
//   channel 0  presence: the cell holds an example when U0 < occupancy x presence;
//   channel 1  rotation: theta = rotate_min + value (rotate_max - rotate_min), in place of U1;
//   channel 2  scale: s = scale_min + value (scale_max - scale_min), in place of U2.
// Channels a layout does not have are drawn from the seed as without a layout.
struct TinyLayout {
  uint32_t width = 0, height = 0, channels = 0;
  const float* values = nullptr;  // width * height * channels, row-major, channels interleaved
};

// Checks a layout's sizes (1..kMaxTinyLayoutSide per side, 1..kMaxTinyLayoutChannels channels) and
// values (finite, in [0, 1]): null when valid, otherwise a short message naming the first problem
// (for a value, its pixel and channel are in *bad_index when given: pixel * channels + channel).
// Safe on untrusted input.
const char* checkTinyLayout(const TinyLayout& layout, uint64_t* bad_index = nullptr);

// Tiles per side of level l of an n x n example: n / 2^(l+1); 0 when l >= levels.
uint32_t tinyTilesPerSide(uint32_t example_size, uint32_t level);
// Bytes of the level section of level l: the 32-byte image header plus tiles^2 x R^2 float32 (or
// binary16 with kTinyFlagHalf).
uint64_t tinyLevelSectionSize(const TinyExampleRecord& record, uint32_t level);

// Checks every field of a record against SPEC.md 10.8 (null when valid, otherwise a short message
// naming the first offending field). Safe on untrusted input.
const char* checkTinyExampleRecord(const TinyExampleRecord& record);

// The smallest cell side that holds every example of the ranges (rotation, scale, shear and the
// shared matrix) whole: twice the largest half-extent of the transformed example square.
double tinyMinCellSize(const TinyExampleRecord& record);
// Expected covered fraction of a stochastic layout: occupancy x E|det M| x n^2 / L^2 (the scale
// uniform on its range). With a layout image (null: none), the mean over its cells of presence x
// |det M| (the cell's scale from channel 2 when it has one).
double tinyCoveredFraction(const TinyExampleRecord& record, const TinyLayout* layout = nullptr);

// One example of a layout: its 2x2 transform M (row-major, positions, y down) and its centre c;
// the example covers {c + M (v - n/2) : v in [0, n)^2}, texel v of the example frame.
struct TinyPlacement {
  bool present = false;
  // The cell holds an example when threshold < occupancy: U0 / presence (infinite for presence 0).
  double threshold = 0.0;
  int64_t cell_x = 0, cell_y = 0;
  double matrix[4] = {1.0, 0.0, 0.0, 1.0};
  double centre[2] = {0.0, 0.0};
};

// The example of stochastic cell (i, j) (present = false for an empty cell). Pure function of the
// record and the cell: the same everywhere (runtime, baker, tests).
// With a layout image (null: none; required when the record's flags say so) its cell's values
// replace the uniforms as TinyLayout says.
// Overlapping layouts (kTinyFlagOverlap): the centre is anywhere in the cell, c = (i + U3, j + U4) L,
// and the example may reach up to kMaxTinyOverlapReach cells beyond it.
TinyPlacement tinyCellPlacement(const TinyExampleRecord& record, int64_t i, int64_t j,
                                const TinyLayout* layout = nullptr);
// The example cell (i, j) would hold with any occupancy (present = true), with its threshold.
TinyPlacement tinyCellCandidate(const TinyExampleRecord& record, int64_t i, int64_t j,
                                const TinyLayout* layout = nullptr);
// Cells an example of an overlapping layout reaches beyond its own: ceil(half extent / L), at most
// kMaxTinyOverlapReach; 0 for layouts without overlaps.
int tinyOverlapReach(const TinyExampleRecord& record);
// Whether the plane point (x, y) lies in the example p (and where, in its frame, in *local).
bool tinyContains(const TinyExampleRecord& record, const TinyPlacement& p, double x, double y, double local[2]);
// The nearest-centre rule: whether example a takes a point at squared distances da (from a's
// centre) and db (from b's) from example b, both covering it: the nearer centre, ties to the
// smaller cell (row j first, then i).
inline bool tinyNearer(double da, const TinyPlacement& a, double db, const TinyPlacement& b) {
  if (da != db) return da < db;
  return a.cell_y != b.cell_y ? a.cell_y < b.cell_y : a.cell_x < b.cell_x;
}
// The fraction of the coverage sample points (kTinyCoverageSamples^2 over kTinyCoverageCells^2
// cells from the origin) some example owns: the covered fraction of an overlapping layout as its
// writer measured it.
double tinySampledCoverage(const TinyExampleRecord& record, const TinyLayout* layout = nullptr);

// The example that covers the point (x, y) of the plane (texels), with the point in the example's
// frame (texels, [0, n)^2) in *local; present = false when no example covers it. Tiled: the copy
// holding the point. Each point belongs to at most one example: examples never overlap, except in
// overlapping layouts, where of the examples covering the point the one with the nearest centre
// owns it (tinyNearer).
TinyPlacement tinyOwner(const TinyExampleRecord& record, double x, double y, double local[2],
                        const TinyLayout* layout = nullptr);

// Inverse of a 2x2 row-major matrix; false when it is singular.
bool tinyInvert(const double m[4], double inv[4]);

}  // namespace glintbake::format
