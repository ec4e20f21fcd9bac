// SPDX-License-Identifier: Apache-2.0
// Runtime-lite reader of tiny-example assets (formats/SPEC.md 10.8): one small example with its
// multi-scale tile NDFs, placed over the unbounded plane, after Xing et al., "Tiny example-based
// procedural microstructures".
//
// The surface. Example texel v (frame [0, n)^2, texels, y down) of the example at centre c with
// transform M lands at u = c + M (v - n/2) (tiled: u = t + M (v + n k), k in Z^2). Its slopes
// follow the inverse transpose: a point s_e of the example's s-plane becomes s = A s_e with
// A = F M^-T F, F = diag(1, -1) (positions have y down, the s-plane y up), so densities transform
// as D(s) = |det M| D_e(M' s) with M' = F M^T F = A^-1. A rotation rotates the NDF, a mirror
// mirrors it, a scale by k divides the slopes by k.
//
// Queries. A Gaussian footprint N((x, y), sigma^2) (texels of the plane) seen in an example's
// frame is N(mu_e, Sigma_e), Sigma_e = sigma^2 M^-1 M^-T. Each example the footprint reaches (its
// 6-sigma window) is entered at its top level (one tile, the whole example) and a tile is split
// into its four children while it is large against the footprint there, weighted by its share of
// the footprint (side t, centre at distance d from mu_e, probability w: w t (d + t) > kTinyRefine
// lambda_min(Sigma_e)) and finer levels exist. A
// kept tile T adds w_T D_T(M' s) |det M|, w_T the footprint's probability over the tile (exact:
// erf products, or the correlated-Gaussian rectangle integral for anisotropic frames), D_T the
// stored bin-averaged image read as piecewise constant. Stochastic surfaces add the flat base
// lobe N(0, sigma_r^2) with the probability no example holds. Above n sigma the periodic sum is the
// top tile.
//
// Small footprints. Below kTinyFlakesExactUpTo every asset answers from the flakes of the plane it
// lays (formats/SPEC.md 10.5 at rate 1): a flake at each plane texel centre with the texel that
// TinyPlaneTexels (and glintquery materialise) gives it and the central differences of its
// neighbours, so the answer equals the reference evaluator on the materialised plane to float
// rounding, for every transform, layout and overlap. Tiled assets whose transform maps the texel
// grid onto itself (multiples of 90 degrees, mirrors) get the same flakes faster from a FlakeNdf
// over the transformed example (TransformedExampleTexels); the others sum the window's flakes per
// query (up to 73 x 73 of them; the texels are read into a 50 kB buffer on the stack). From
// kTinyFlakesExactUpTo to kTinyFlakesUpTo the flakes' answer and the tiles' are blended linearly in
// log(sigma); sample() picks one of the two in proportion to its share of the mass.
//
// Contract (NdfSource): eval() is the sum above inside [-1, 1]^2 and 0 outside; average() its
// exact mean over a rectangle (the transformed rectangle clipped against the stored bins);
// image() those bin averages with bins whose centre lies outside the unit disk set to 0; mass()
// the integral over the plane, sum w_T m_T (m_T the tile image's integral); sample() picks a tile
// in proportion to w_T m_T, a bin of it, a uniform point in the bin, maps it by A and returns
// pdf() at that point (eval / mass, bit for bit); a point mapped outside [-1, 1]^2 comes back with
// pdf 0 (a failed sample, as with the flakes). Queries are const, thread-safe, never allocate and
// never throw. load() is safe on untrusted input.
#pragma once

#include <glintbake/format/kinds/tiny_example.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/texel_source.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace glintbake::runtime {

constexpr double kTinyRefine = 0.005;  // split a tile while w t (d + t) > kTinyRefine lambda_min
// Footprints (sigma, texels) below kTinyFlakesExactUpTo are answered by the flakes alone, from
// kTinyFlakesUpTo on by the tiles alone, and between by both, blended linearly in log(sigma).
constexpr double kTinyFlakesExactUpTo = 4.0;
constexpr double kTinyFlakesUpTo = 6.0;
constexpr double kTinyWindowSigmas = 6.0;
// Stochastic layouts: most layout cells one query visits (48 x 48; wider footprints are clamped,
// see footprintRange). Tiled: most copies of the example one query visits (only footprints far
// narrower across one axis of the transform than along the other reach it before the top tile).
constexpr int64_t kTinyMaxCells = 48 * 48;
constexpr int64_t kTinyMaxCopies = int64_t(1) << 18;

// The bin-averaged NDF image (R x R, row 0 at s_y = +1, bins outside the unit disk 0) of the texels
// [x0, x0 + side) x [y0, y0 + side) of an n x n example: the mean over those texels of their lobes
// N(s; n_k, sigma_r^2 I + sigma_h^2 J_k J_k^T) (the flake model of formats/SPEC.md 10.5 at rate 1,
// integrated over position; J_k from the example with its wrap). texels: n * n (n_x, n_y) pairs.
// out: R * R floats. kInvalidArgument for sizes out of range. Thread-safe, no allocation.
RuntimeStatus tinyTileImage(const float* texels, int n, bool repeats, double sigma_r, int resolution, int x0, int y0,
                            int side, float* out);

// The example under one of the eight transforms that map the texel grid onto itself (matrix with
// entries in {-1, 0, 1}, one non-zero per row and column): an n x n grid whose texel g is example
// texel M^-1 (g + 1/2 + o) - 1/2 (o the corner of M [0, n]^2), with its normal mapped by A.
class TransformedExampleTexels final : public TexelSource {
 public:
  // False (and an identity source) when matrix is not such a transform.
  static bool isGridTransform(const double matrix[4]);
  TransformedExampleTexels(const float* texels, int n, bool repeats, const double matrix[4]);
  int width() const override { return n_; }
  int height() const override { return n_; }
  bool repeats() const override { return repeats_; }
  void normal(int x, int y, float out[2]) const override;
  // Where grid texel (0, 0)'s corner lies relative to M's image of the example corner: o.
  double offsetX() const { return off_[0]; }
  double offsetY() const { return off_[1]; }

 private:
  const float* texels_;
  int n_;
  bool repeats_;
  int m_[4];
  double off_[2];
};

class TinyExampleNdf;

// Largest |(n_x, n_y)| a materialised texel keeps: a slope the transform pushes out of the unit disk
// (scales below 1 steepen slopes) is shortened to this length, keeping its direction.
constexpr double kTinyMaxMaterialisedSlope = 0.999;

// The texels [x0, x0 + width) x [y0, y0 + height) of an asset's plane (texels, y down) as a normal
// map: the surface the asset answers for, for the reference evaluator and the renderer. Texel
// (x, y) is the plane point p = (x0 + x + 1/2, y0 + y + 1/2): the example owning p (format::tinyOwner)
// is read at p's position in its frame, bilinearly between texel centres with the example repeating
// (so a transform that maps the texel grid onto itself reproduces the texels exactly), and its
// (n_x, n_y) is mapped by A = F M^-T F as the runtime maps slopes (at most
// kTinyMaxMaterialisedSlope long); points no example owns are flat (0, 0). Continues with its edge
// texels beyond the rectangle. The asset must be open and outlive the source.
class TinyPlaneTexels final : public TexelSource {
 public:
  TinyPlaneTexels(const TinyExampleNdf& asset, int64_t x0, int64_t y0, int width, int height);
  int width() const override { return width_; }
  int height() const override { return height_; }
  bool repeats() const override { return false; }
  void normal(int x, int y, float out[2]) const override { texel(x, y, out); }
  // normal(), and whether an example owns the texel (false: flat).
  bool texel(int x, int y, float out[2]) const;

 private:
  const TinyExampleNdf& asset_;
  int64_t x0_, y0_;
  int width_, height_;
};

class TinyExampleNdf final : public NdfSource {
 public:
  TinyExampleNdf();
  ~TinyExampleNdf() override;
  TinyExampleNdf(const TinyExampleNdf&) = delete;
  TinyExampleNdf& operator=(const TinyExampleNdf&) = delete;

  // kIoError, kInvalidAsset, kWrongKind, kUnsupportedVersion, kOutOfMemory.
  RuntimeStatus open(const char* path);
  RuntimeStatus openMemory(const void* data, size_t size);
  RuntimeStatus load(const format::Reader& reader);
  bool isOpen() const { return open_; }

  const format::TinyExampleRecord& record() const { return record_; }
  // The example's n * n (n_x, n_y) texels (row-major), or null when closed.
  const float* texels() const { return open_ ? texels_.data() : nullptr; }
  // The stochastic layout image (format::TinyLayout), or null when the asset has none.
  const format::TinyLayout* layout() const { return open_ && layout_.values ? &layout_ : nullptr; }
  // The stored tile image of (level, tile index row-major) (R * R floats), or null.
  const float* tileImage(int level, int tile) const;
  // Every open asset answers small footprints from flakes (exactly: the flake model of the plane
  // as TinyPlaneTexels lays it).
  bool hasFlakes() const { return open_; }
  // Whether they come from a FlakeNdf over the transformed example (tiled assets whose transform
  // maps the texel grid onto itself: faster, the same answer) rather than the plane texels.
  bool hasGridFlakes() const { return open_ && flakes_ && flakes_->isBuilt(); }

  format::AssetKind kind() const override { return format::AssetKind::kTinyExample; }
  int resolution() const override { return open_ ? int(record_.ndf_res) : 0; }
  // pyramid_min_sigma 2 (the finest tiles), exact_max_sigma and handover_max_sigma the flakes' band.
  // Stochastic layouts: pyramid_max_sigma is the widest footprint whose 6-sigma window (and, with
  // overlaps, the cells around it) stays within kTinyMaxCells cells, about 3.5 cells; wider
  // footprints are answered as that one at the same centre (a clamp, as the pyramids' top level:
  // such a window already holds some 1,500 examples, so its NDF is close to the layout's mean).
  // Tiled: no clamp (the periodic sum is the top tile from n sigma on).
  FootprintRange footprintRange() const override;
  // The example's size (the plane is unbounded).
  MapSize mapSize() const override;
  MapWrap wrap() const override { return MapWrap::kUnbounded; }

  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus mass(const Footprint& footprint, double* value) const override;
  RuntimeStatus image(const Footprint& footprint, float* out, size_t out_count) const override;

  // Tiles (and the base) a footprint combines, for tests and benchmarks: examples entered and tiles
  // kept. kInvalidArgument as the queries.
  RuntimeStatus traversalCount(const Footprint& footprint, int64_t* examples, int64_t* tiles) const;

  struct Frame;
  struct Visit;
  struct Batch;

 private:
  bool validFootprint(const Footprint& f) const;
  Footprint flakeFootprint(const Footprint& f) const;
  template <typename F>
  bool planeFlakes(const Footprint& f, F&& lobe) const;
  RuntimeStatus flakeEval(const Footprint& f, const SPoint& s, double* value) const;
  RuntimeStatus flakeMass(const Footprint& f, double* value) const;
  RuntimeStatus flakeAverage(const Footprint& f, const SRect& rect, double* value) const;
  RuntimeStatus addFlakeImage(const Footprint& f, double weight, float* out) const;
  // total: flakeMass() of the footprint.
  RuntimeStatus flakeSample(const Footprint& f, double total, double u1, double u2, NdfSample* sample) const;
  RuntimeStatus tileEval(const Footprint& f, const SPoint& s, double* value) const;
  RuntimeStatus tileMass(const Footprint& f, double* value) const;
  RuntimeStatus tileAverage(const Footprint& f, const SRect& rect, double* value) const;
  RuntimeStatus addTileImage(const Footprint& f, double weight, float* out) const;
  // total: tileMass() of the footprint.
  RuntimeStatus tileSample(const Footprint& f, double total, double u1, double u2, NdfSample* sample) const;
  template <typename F>
  bool traverse(const Footprint& f, F&& visit, int64_t* entered = nullptr) const;
  // traverse(), handing the tiles over in batches of one frame.
  template <typename F>
  bool batched(const Footprint& f, F&& flush) const;

  bool open_ = false;
  format::TinyExampleRecord record_;
  std::vector<float> texels_;
  std::vector<std::vector<float>> levels_;  // per level: tiles^2 images of R^2
  std::vector<std::vector<double>> tile_mass_;
  std::vector<std::vector<double>> row_mass_;  // per level: tiles^2 x R row integrals
  std::vector<float> layout_values_;           // section 115 (version 2 with a layout)
  format::TinyLayout layout_;
  std::vector<float> base_;  // the flat lobe (stochastic surfaces)
  std::vector<double> base_rows_;
  double base_mass_ = 0.0;
  std::unique_ptr<FlakeNdf> flakes_;
  std::unique_ptr<TransformedExampleTexels> flake_texels_;
};

}  // namespace glintbake::runtime
