// SPDX-License-Identifier: Apache-2.0
// Tiny examples (Xing et al., "Tiny example-based procedural microstructures"): the multi-scale
// tile NDFs of one small normal-map example and the records of its tiny-example asset
// (formats/SPEC.md 10.8).
//
// Level l of an n x n example holds m = n / 2^(l+1) tiles per side, each 2^(l+1) texels wide; a
// tile's NDF is the mean of its texels' lobes (runtime::tinyTileImage: bin-integrated, R x R), and
// a coarser tile is the mean of its four children (the same mean over the same texels).
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/result.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/tiny_example.h>

#include <cstdint>
#include <vector>

namespace glintbake::bake::tiny {

// The placement of the examples.
struct TinyPlacementOptions {
  format::TinyExampleType type = format::TinyExampleType::kTiled;
  double rotate_range[2] = {0.0, 0.0};  // degrees; tiled: both ends equal (--rotate)
  double scale_range[2] = {1.0, 1.0};   // tiled: both ends equal
  double shear[2] = {0.0, 0.0};
  bool mirror = false;               // mirror every example left to right (x -> -x) before the other transforms
  double translate[2] = {0.0, 0.0};  // tiled only
  uint64_t seed = 0;                 // stochastic only
  double density = 1.0;              // stochastic only: covered fraction, (0, 1]
  // Stochastic only: a layout image (format::TinyLayout, caller-owned values; width 0: none). With a
  // layout the occupancy is 1 (presence as the image says) unless density_given, when it is scaled
  // so that the expected covered fraction is `density`.
  format::TinyLayout layout;
  bool density_given = false;
  // Stochastic only: overlapping examples (version 2, kTinyFlagOverlap): cells smaller than the
  // examples, centres anywhere in their cell, each point owned by the nearest centre covering it;
  // the cell side and occupancy are chosen so that the covered fraction measured on the coverage
  // sample points (format::tinySampledCoverage) equals the density.
  bool overlap = false;
};

// The record of an example of size n with the given placement, NDF resolution and roughness:
// tiled: matrix = R H S (mirror); stochastic: the smallest cell holding every example and the
// occupancy giving the density; with a layout image, version 2 with kTinyFlagLayout. kBadArgument
// (message naming the option) for values out of range, including a density larger than the layout
// can cover; kInvalidInput for a layout image checkTinyLayout refuses.
Result<format::TinyExampleRecord> makeTinyRecord(int n, int ndf_res, double sigma_r, const TinyPlacementOptions& p);

// Checks an example map: square, a power of two in [4, 256] (kBadArgument otherwise, naming the size).
BakeStatus checkTinyExample(const NormalMap& example);

// The (n_x, n_y) pairs of the example (n * n * 2 floats, row-major).
std::vector<float> tinyTexels(const NormalMap& example);

// Every level's tile images: levels[l] holds m^2 images of R^2 floats (tile index row-major).
// Parallel over tiles (TBB, honouring the caller's arena); the same bytes for any thread count.
std::vector<std::vector<float>> bakeTinyLevels(const std::vector<float>& texels, int n, double sigma_r, int ndf_res);

// Whether every tile value fits binary16 (at most format::kTinyHalfMax), as kTinyFlagHalf needs.
bool tinyLevelsFitHalf(const std::vector<std::vector<float>>& levels);
// The record with its levels stored as binary16 (version 2, kTinyFlagHalf).
format::TinyExampleRecord withHalfLevels(format::TinyExampleRecord record);

// Adds the info, texels and level sections (binary16 when the record has kTinyFlagHalf) (checked by
// format::checkTinyExampleRecord first), and the layout section when the record has kTinyFlagLayout (layout then
// required and checked).
BakeStatus writeTinyExampleSections(format::Writer& writer, const format::TinyExampleRecord& record,
                                    const std::vector<float>& texels, const std::vector<std::vector<float>>& levels,
                                    const format::TinyLayout* layout = nullptr);

// The tiled surface materialised over copies x copies examples (identity transform): the normal
// map the reference evaluator compares against.
NormalMap materialiseTiled(const NormalMap& example, int copies);

}  // namespace glintbake::bake::tiny
