// SPDX-License-Identifier: Apache-2.0
// Procedural microstructure normal maps with known statistics, for tests, benchmarks and examples.
//
// Every map is periodic (tileable: wrap mode repeat) and a pure function of (kind, params): the
// random numbers are drawn from a counter-based generator (splitmix64 of seed, stream and texel or
// element index) with a Box-Muller transform written here, so the bytes do not depend on the
// standard library, the thread count or the scheduling.
//
// Kinds:
//  - flat:      every normal (0, 0, 1).
//  - beckmann:  an isotropic Gaussian random height field h = w * g, white Gaussian noise w
//               circularly convolved with a Gaussian kernel g of standard deviation `cell` texels
//               (default 3; the height autocorrelation is then Gaussian with standard deviation
//               cell * sqrt(2)). Slopes are the exact derivatives of that smooth surface, scaled
//               so that each slope (dh/dx, dh/dy) ~ N(0, alpha^2 / 2): the Beckmann distribution
//               of roughness alpha (Walter et al. 2007, section 5.1). n = normalize(-dh/dx, -dh/dy, 1).
//  - brushed:   the same with an anisotropic kernel: standard deviation `cell` across the brushing
//               direction (y) and cell * alpha_y / alpha_x along it (x), capped at size / 4, and
//               slopes scaled to N(0, alpha_x^2 / 2) and N(0, alpha_y^2 / 2). With alpha_x < alpha_y
//               the grooves run along x. Below the cap one height field explains both slopes.
//  - scratches: a flat base with straight V-groove scratches: density per 1000 texel^2 of map,
//               width in texels, lengths uniform in [10%, 50%] of the map side, directions
//               uniform; each groove wall has slope `scratch_slope` (height units per texel).
//               Overlapping grooves add their heights. Each texel averages 4x4 sub-samples.
//  - flakes:    periodic Voronoi cells around size^2 / cell^2 uniformly placed sites (mean cell
//               area cell^2 texels); each cell has one normal drawn uniformly (in solid angle) from
//               the cone of half-angle `cone_degrees` around z.
//
// Units: sizes, widths and cells in texels; slopes in height units per texel (the tangent-frame
// slope of the normal, -n_x / n_z). Coordinates follow formats/SPEC.md: x right, y up (rows go
// down), texel centres at (c + 0.5, r + 0.5).
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/result.h>

#include <cstdint>
#include <string>

namespace glintbake::bake {

enum class MapKind { kFlat, kBeckmann, kBrushed, kScratches, kFlakes };

// "flat", "beckmann", "brushed", "scratches", "flakes".
const char* mapKindString(MapKind kind);
// Parses the names above (exact, lower case). Returns false for anything else.
bool mapKindFromString(const std::string& name, MapKind* kind);
// The names above separated by ", " (for help texts and error messages).
std::string mapKindList();

struct MapParams {
  int size = 256;              // width and height in texels, >= 1
  uint64_t seed = 1;           // any value; equal seeds give equal maps
  double alpha = 0.3;          // beckmann: roughness, (0, 4]
  double alpha_x = 0.05;       // brushed: roughness along x (the brushing direction), (0, 4]
  double alpha_y = 0.3;        // brushed: roughness along y, (0, 4]
  double density = 2.0;        // scratches: per 1000 texel^2, [0, 1000]
  double width = 2.0;          // scratches: groove width in texels, (0, 256]
  double scratch_slope = 0.5;  // scratches: wall slope, (0, 10]
  double cone_degrees = 10.0;  // flakes: half-angle of the normal cone, [0, 89]
  double cell = 0.0;           // beckmann/brushed: kernel std (texels, (0, size/2]); flakes: mean
                               // cell size (texels, [1, size]); 0 = the kind's default (below)
};

// Kind defaults for MapParams::cell == 0. The Gaussian kernel default is clamped to size / 4 on
// small maps so that the default parameters work at every size.
constexpr double kDefaultGaussianCell = 3.0;
constexpr double kDefaultFlakeCell = 8.0;
double effectiveCell(MapKind kind, const MapParams& params);

// Checks the parameters that `kind` uses; the error (kBadArgument) names the parameter, its value
// and the accepted range. Parameters the kind does not use are not checked.
BakeStatus validateMapParams(MapKind kind, const MapParams& params);

// Generates the map (wrap mode repeat, unit normals, n_z > 0). The parameters must pass
// validateMapParams (checked: violating it aborts). Multithreaded with TBB; the result is
// identical for every thread count. Cost: O(size^2 * cell) for the Gaussian kinds, O(size^2) for
// flakes, O(scratch area) for scratches; peak memory at most 7 floats per texel.
NormalMap generateMap(MapKind kind, const MapParams& params);

// Statistics of a map of unit normals with n_z > 0 (texels with n_z <= 1e-6 are skipped for the
// slopes). Reductions run in a fixed order: the result is deterministic.
struct MapStatistics {
  double mean_normal[3] = {0.0, 0.0, 0.0};  // average of the unit normals (not renormalised)
  double slope_mean[2] = {0.0, 0.0};        // mean of (-n_x / n_z, -n_y / n_z)
  double slope_std[2] = {0.0, 0.0};         // standard deviation of the same, per axis
  double max_angle_degrees = 0.0;           // largest angle between a normal and z
  int64_t texels = 0;
};
MapStatistics measureMap(const NormalMap& map);

}  // namespace glintbake::bake
