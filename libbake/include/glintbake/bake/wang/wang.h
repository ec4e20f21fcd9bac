// SPDX-License-Identifier: Apache-2.0
// Wang tiles from an example normal map (Cohen et al. 2003, "Wang Tiles for Image and Texture
// Generation", section 3) and the per-tile NDF assets of a wang-tiles container (formats/SPEC.md
// 10.7; Deng et al. 2022 section 5.5).
//
// Tile set. For C colours there are C colours of horizontal (N/S) and C of vertical (E/W) edges and
// the complete set of C^4 tiles, one per edge code ((N C + E) C + S) C + W. Each edge colour is a
// sample of the exemplar at a seeded random offset, laid so that its middle line runs along the
// edge: a tile shows each of its four samples in the triangle between its centre and that edge
// (the diamond of Cohen et al.: the neighbour across the edge shows the other half of the same
// sample). The four triangles meet along the tile's diagonals, where a minimum-error cut
// (quilting, dynamic programming over the lines perpendicular to the diagonal, error = angle
// between the two samples' normals) replaces the straight cut in a band that narrows to nothing
// at the corners and at the centre.
//
// Exact edges. The two texel rows (columns) on either side of an edge read the same exemplar row
// (column), and the four texels around every grid vertex are one texel of the exemplar. So every
// tile's outer ring depends only on its edge colours, and a tile read with clamped edges (what its
// own flakes see: central differences one texel across) continues exactly as the plane of tiles
// does: the flakes of the implicit grid at rate 1 are the flakes of the tiles, each taken alone.
//
// Thread safety: the functions are reentrant; buildWangTiles and bakeWangTileNdf use TBB.
// Determinism: results depend only on the inputs and options, never on the thread count.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/result.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/wang.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::bake::wang {

struct WangTileOptions {
  int colors = 2;        // C, [2, 4]
  int tile_size = 256;   // T texels, [8, 4096], at most the exemplar's width and height
  uint64_t seed = 0;     // selects the edge samples
  bool optimise = true;  // minimum-error cuts (false: the straight diagonal cuts)
  int band = 0;          // half-width of the cut's band in texels (0: T / 8)
};

// Angles (degrees) between the two samples' normals at the texels along the cuts.
struct SeamError {
  double mean_degrees = 0.0;
  double max_degrees = 0.0;
  uint64_t texels = 0;
};

struct WangTileSet {
  int colors = 0;
  int tile_size = 0;
  int tile_count = 0;
  std::vector<std::array<uint8_t, 4>> edges;  // per tile: N, E, S, W colours (tile index = its code)
  std::vector<float> normals;                 // tile after tile, T x T x 3 (x, y, z), row 0 at the top
  SeamError seam;                             // along the cuts used
  SeamError plain_seam;                       // along the straight cuts, for comparison

  // Tile t as a clamped normal map of T x T texels.
  NormalMap tile(int t) const;
  const float* texel(int t, int x, int y) const {
    return &normals[((size_t(t) * size_t(tile_size) + size_t(y)) * size_t(tile_size) + size_t(x)) * 3];
  }
};

// Builds the complete tile set. kBadArgument for options out of range (naming the option),
// kInvalidInput for an exemplar smaller than the tile size.
Result<WangTileSet> buildWangTiles(const NormalMap& exemplar, const WangTileOptions& options);

// The region of the implicit grid of cells [i0, i0 + nx) x [j0, j0 + ny) as one clamped normal map
// (nx T x ny T texels): each cell shows the tile of its hashed edge code (format::wangCellEdges).
NormalMap materialiseWangRegion(const WangTileSet& set, uint64_t grid_seed, int64_t i0, int64_t j0, int nx, int ny);

// The tile atlas: all tiles side by side, sqrt-ish grid of ceil(sqrt(N)) columns, as a clamped map.
NormalMap wangAtlas(const WangTileSet& set);

// Per-tile NDF asset options: the pyramid covers the tile's square extended by `margin` texels on
// every side (footprint centres outside the tile), each image splatting only the tile's flakes.
struct WangNdfOptions {
  ndf::PyramidOptions pyramid;
  tensor::TensorPackOptions pack;  // compression; ignored when uncompressed
  bool uncompressed = false;       // an ndf-pyramid asset instead of a tensor-ndf one
  int margin = 0;                  // texels, >= 1
  int zstd_level = 9;
};

struct WangTileNdfReport {
  tensor::TensorPackReport pack;  // compressed tiles
  ndf::PyramidReport pyramid;     // uncompressed tiles
};

// Bakes tile t's NDF asset into a container at `path` (written atomically) with the given metadata
// JSON, then reads its bytes into *bytes and removes the file. Errors: kBadArgument (options),
// kRuntime, kIo.
BakeStatus bakeWangTileNdf(const WangTileSet& set, int t, const WangNdfOptions& options, const std::string& path,
                           const std::string& metadata_json, std::vector<uint8_t>* bytes, WangTileNdfReport* report,
                           const std::atomic<bool>* cancel = nullptr);

// The wang-tiles record of a tile set (grid seed, NDF geometry and hand-over as given) and the
// sections of a wang-tiles container: record, edges, texels, then the tiles' NDF assets (bytes of
// bakeWangTileNdf, tile order) added to an open writer (the caller adds metadata and finishes).
// kBadArgument when the record fails its check or the tile count differs, kIo on writer failure.
format::WangRecord wangRecord(const WangTileSet& set, const WangNdfOptions& options, uint64_t grid_seed,
                              double flakes_up_to, double pyramid_from, double max_sigma);
BakeStatus writeWangSections(format::Writer& writer, const WangTileSet& set, const format::WangRecord& record,
                             const std::vector<std::vector<uint8_t>>& tile_assets);

// The sections before the tiles' assets (record, edges, texels), in the order writeWangSections
// adds them: for writers that place them themselves (sharded bakes). kBadArgument when the record
// fails its check or its tile count differs from the set's.
struct WangSection {
  uint32_t type = 0;
  std::vector<uint8_t> bytes;
};
Result<std::vector<WangSection>> wangCommonSections(const WangTileSet& set, const format::WangRecord& record);

}  // namespace glintbake::bake::wang
