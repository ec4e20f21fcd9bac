// SPDX-License-Identifier: Apache-2.0
// The NDF of an unbounded surface tiled by Wang tiles on an implicit hashed grid (formats/SPEC.md
// 10.7; Cohen et al. 2003, Lagae and Dutre 2005, Deng et al. 2022 section 5.5).
//
// Positions are texels of the plane: cell (i, j) = floor(x / T), floor(y / T) holds the tile whose
// edge code its hashed vertices give (format::wangCellEdges), with its texel (0, 0) at (i T, j T).
// Any finite position is valid; storage is that of the tile set whatever area is covered.
//
// A footprint's NDF is the sum over the tiles it covers of each tile's own contribution: from the
// tiles' flakes (a FlakeNdf per tile over the tile's texels; their clamped edges continue exactly as
// the grid does, so at rate 1 this is the flake model of the plane) for sigma <= flakes_up_to, from
// each tile's NDF asset (a tensor-ndf or ndf-pyramid over the tile's square extended by the margin,
// queried at the footprint's position relative to the tile plus the margin) for sigma >=
// pyramid_from, and a blend linear in log sigma between the two. A tile counts when the footprint's
// window (4 sqrt(sigma_h^2 + sigma^2) texels for the assets, 1.5 times that for the flakes) meets
// it.
//
// Maximum footprint: sigma above max_sigma (T / 4, less a hair: format::wangMaxSigma) is clamped to
// it, so that a footprint meets at most 3 x 3 tiles and a query costs at most 9 (or, in the
// hand-over band, 18) tile queries.
//
// sample() picks a (path, tile) term in proportion to its weighted mass and samples within it;
// pdf() is eval() / mass() computed by the same sums, so a sample's pdf equals eval / mass exactly.
// Queries are const and thread-safe and never throw; image() uses one R x R scratch buffer per
// thread (allocated on a thread's first image() call), the other queries never allocate.
// Memory: the tiles' assets plus about 36 bytes per flake of every tile.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/kinds/wang.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/texel_source.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace glintbake::runtime {

class WangNdf final : public NdfSource {
 public:
  WangNdf();
  ~WangNdf() override;
  WangNdf(const WangNdf&) = delete;
  WangNdf& operator=(const WangNdf&) = delete;

  // Loads every section of a wang-tiles container and opens each tile's NDF asset. kWrongKind,
  // kInvalidAsset (any record, size or embedded asset inconsistent), kUnsupportedVersion,
  // kOutOfMemory. Safe on untrusted input.
  RuntimeStatus load(const format::Reader& reader);

  format::AssetKind kind() const override { return format::AssetKind::kWangTiles; }
  int resolution() const override;
  FootprintRange footprintRange() const override;
  // One tile's size (the surface itself is unbounded) and kRepeat.
  MapSize mapSize() const override;
  MapWrap wrap() const override { return MapWrap::kUnbounded; }

  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus mass(const Footprint& footprint, double* value) const override;
  RuntimeStatus image(const Footprint& footprint, float* out, size_t out_count) const override;

  const format::WangRecord& record() const;
  // The tile of grid cell (i, j), and the tiles' (n_x, n_y) texels (see WangGridTexels).
  uint32_t cellTile(int64_t i, int64_t j) const;
  const float* tileTexels() const;
  // Tiles a footprint's terms involve (1..9; the clamped sigma's window): for benchmarks and tests.
  int coveredTiles(const Footprint& footprint) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The texels of a rectangle of cells of an asset's implicit grid, [i0, i0 + nx) x [j0, j0 + ny),
// as the grid lays its tiles: a TexelSource for evaluating a materialised region with the flake
// evaluator (FlakeNdf), clamped at the rectangle's edges. The asset must outlive the source.
class WangGridTexels final : public TexelSource {
 public:
  WangGridTexels(const WangNdf& asset, int64_t i0, int64_t j0, int nx, int ny);
  int width() const override { return nx_ * tile_size_; }
  int height() const override { return ny_ * tile_size_; }
  bool repeats() const override { return false; }
  void normal(int x, int y, float out[2]) const override;

 private:
  const float* texels_;
  int tile_size_, nx_, ny_;
  std::vector<uint32_t> tiles_;  // tile of each cell of the rectangle, row-major
};

}  // namespace glintbake::runtime
