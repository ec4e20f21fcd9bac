// SPDX-License-Identifier: Apache-2.0
// Streams a multi-level pyramid of footprint NDF images (Deng et al. 2022, "Constant-Cost
// Spatio-Angular Prefiltering of Glinty Appearance Using Tensor Decomposition", ACM TOG) into an ndf-pyramid container,
// or into any PyramidSink.
//
// Level l: footprint std sigma_l = sigma0 * 2^l texels; grid_width = max(1, round(map_width /
// (stride0 * 2^l))) centres per row (likewise per column), actual stride = map size / grid size
// (so a repeating map's grid is exactly periodic), centre (i, j) at ((i + 0.5) stride_x,
// (j + 0.5) stride_y). When the grid sizes halve exactly, each level-(l+1) centre is the centre of
// the 2 x 2 block of level-l centres below it, like mip-map texel centres.
//
// Streaming: each level is cut into regions of region_size x region_size centres; the images of one
// region are computed in parallel (each image independently, by one thread, so results do not
// depend on the thread count), then handed to a PyramidSink (for ndf-pyramid assets: written as one
// kSectionNdfChunk section; tensorpack compresses them instead) while the next region is computed.
// Footprints with more than 2^18 flakes (the top levels: few images, each up to several maps' worth
// of flakes) are instead split into 16 interleaved row sets computed in parallel and summed in a
// fixed order (still independent of the thread count). Peak memory: the flakes (24 bytes per
// flake) plus two chunks (2 * region_size^2 * R^2 * 4 bytes; 32 MiB at the defaults) plus scratch
// (R^2 * 8 bytes per thread and 16 R^2 * 8 for split footprints), plus what the sink keeps
// (README.md, "Figures", has measured peaks).
//
// Automatic level count (levels = 0): before level l >= 1 is computed, its images at up to 4 x 4
// evenly spread centres (at most a quarter of the level's centres, at least one) are computed and compared with what
// the runtime predicts there from level l - 1 (the bilinear blend of the level-(l-1) images around that position,
// collected while level l - 1 was written): relative MSE = sum |D_l - P_l|^2 / sum |P_l|^2, averaged over the samples.
// If it is below converge_mse, level l would add little (queries above the top level clamp to it,
// and its blend already predicts level l within the tolerance), so the pyramid stops without
// computing it (stop reason "converged"; the probe's MSE is reported). Otherwise the probed images
// are reused when their regions are computed, so the probe costs nothing extra. The pyramid also
// stops after the first level whose grid is 1 x 1 (the stride reached the map size and, on a
// repeating map, the footprint is flat over it: levelGeometry; on a clamped map, once its sigma
// is kClampedFlatSigma times the longer side), or at kMaxPyramidLevels (README.md, "Figures":
// what skipping the converged level saves).
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/ndf/splat.h>
#include <glintbake/bake/result.h>
#include <glintbake/bake/shard/shard.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/ndf_pyramid.h>
#include <glintbake/format/kinds/ndf_pyramid_blend.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace glintbake::bake::ndf {

constexpr int kMaxPyramidLevels = 24;

struct PyramidOptions {
  SplatParams splat;           // R (ndf_res), sigma_r, truncation radii
  int rate = 1;                // flakes per texel side, [1, kMaxFlakeRate]
  double stride0 = 16.0;       // level-0 stride, texels, > 0
  double sigma0 = 8.0;         // level-0 footprint std, texels, > 0
  int levels = 0;              // 0 = automatic, else exactly this many, [1, kMaxPyramidLevels]
  double converge_mse = 1e-2;  // relative MSE threshold of the automatic level count, > 0
  int region_size = 16;        // centres per region side, [1, 256]
  // Automatic level count: the convergence test runs only above a level of at most this many
  // centres per side (0: above every level). The default is the runtime's whole-grid blend
  // (format::kWholeGridAxis): a repeating map's top level of at most 16 x 16 centres answers every
  // wider footprint with the mean of its centres over the footprint, where a larger top grid is
  // spread by at most 2.5 strides, a clamp that footprints far above it see as the wrong NDF (on
  // a brushed 1024^2 map, a pyramid that stopped at its level 0 scored 0.09-0.10 relative L1 at
  // 48-128 texels, worse than the whole map's NDF). tensorpack also makes the pyramid reach the
  // small levels it stores exactly.
  int converge_from_grid = format::kWholeGridAxis;
  int converge_from_level = 0;  // ... and only above this level
  // Sharded bakes (bake/shard/shard.h): when set, only the regions it accepts are computed and
  // handed to the sink (addChunk); the others are announced with skipChunk, and of their centres
  // only those the automatic level count samples are computed, so that every shard takes the same
  // level-count decision as the whole bake. Called from the building thread only.
  std::function<bool(int level, int region)> region_filter;
};

// Validates the options (kBadArgument with a message naming the option).
BakeStatus validatePyramidOptions(const PyramidOptions& options);

struct LevelGeometry {
  int grid_width = 0, grid_height = 0;
  double stride_x = 0.0, stride_y = 0.0;  // texels
  double sigma = 0.0;                     // texels
  int regions_x = 0, regions_y = 0;
};
// A level's centres tile the map at the stride rounded to a whole number per axis. The runtime
// widens a footprint by mixing the level's centres (formats/SPEC.md 10.1), which a single centre
// along an axis cannot do, and a Gaussian footprint of std sigma on an axis of period P weighs the
// texels with a ripple of 2 exp(-2 pi^2 sigma^2 / P^2) (18% at sigma = 0.35 P), which only
// centres that partition the axis (splat.h, footprintPartition) take out. So where the footprints
// wrap (`periodic`: a repeating map's own flakes), a level keeps at least two centres along any
// axis whose period exceeds its sigma / kFlatAxisSigma: one centre only where the footprint is
// already flat along the axis (ripple 1e-3). On a 37 x 23 map the top level of one centre of
// sigma 16 gave the whole map's NDF to 0.03 relative L1, and its level 0 (one centre along the
// 23 texels) 0.10 at 32 texels.
constexpr double kFlatAxisSigma = 0.62;
// A clamped map has no surface beyond its edges: a footprint far wider than the map keeps only the
// mass over it (the runtime's edge falloff, formats/SPEC.md 10.1) with the shape of the top level's
// image, whose footprint weighs the middle of the map more than its edges. So the automatic level
// count adds levels of one centre until sigma is this many times the longer side, where the
// weights over the map vary by exp(-1/32) (3%) from its centre to the middle of an edge. On a
// 128^2 tufted-leather map the top level of sigma 64 gave 0.092 relative L1 at 128 texels.
constexpr double kClampedFlatSigma = 2.0;
LevelGeometry levelGeometry(int map_width, int map_height, const PyramidOptions& options, int level, bool periodic);

struct PyramidLevelReport {
  int level = 0;
  LevelGeometry geometry;
  uint64_t images = 0;
  uint64_t raw_bytes = 0;       // uncompressed chunk bytes
  uint64_t stored_bytes = 0;    // bytes the level added to the file
  double seconds = 0.0;         // wall time of the level
  double mse_vs_previous = -1;  // sampled relative MSE against the prediction from the level below (-1: level 0)
};

struct PyramidReport {
  std::vector<PyramidLevelReport> levels;
  std::string stop_reason;     // "levels", "converged", "grid-1x1", "max-levels"
  double next_level_mse = -1;  // "converged": sampled relative MSE of the level that was not needed
  uint64_t flakes = 0;
  double flake_seconds = 0.0;
};

// Progress: called from the writing thread after each chunk with (images done, images of level).
using PyramidProgress = std::function<void(int level, uint64_t done, uint64_t total)>;

// One finished region of one level, as handed to a PyramidSink. The images are laid out as an
// image section (formats/SPEC.md 3.1): `section` points at a format::ImageSectionHeader (width =
// height = ndf_res, channels 1, layers = centres) directly followed by `images`, so a sink can
// store the chunk without a copy. The region's centres are in row-major order within the region:
// centre k is grid centre (x0 + k % width, y0 + k / width). Pointers are valid during the call only.
struct PyramidChunk {
  int level = 0;
  int region = 0;                 // ry * regions_x + rx
  int x0 = 0, y0 = 0;             // first centre of the region on the level's grid
  int width = 0, height = 0;      // centres of the region per row / column
  int ndf_res = 0;                // R
  const float* images = nullptr;  // width * height * R * R floats, image after image
  const void* section = nullptr;  // header + images, section_bytes long
  size_t section_bytes = 0;
};

// Receives the pyramid as it is built, from the calling thread of buildNdfPyramid, in this order:
// for each level, addLevel, then addChunk for every region in region order, then endLevel. A sink
// may take long in addChunk: the next region is being computed on the TBB pool meanwhile, so a
// sink that spawns its own TBB tasks keeps every core busy. A failing status stops the build and
// is returned by buildNdfPyramid.
class PyramidSink {
 public:
  virtual ~PyramidSink() = default;
  virtual BakeStatus addLevel(const format::NdfLevelRecord& record) = 0;
  virtual BakeStatus addChunk(const PyramidChunk& chunk) = 0;
  virtual BakeStatus endLevel(int level) { return (void)level, okStatus(); }
  // A region PyramidOptions::region_filter refused, in its place in the region order.
  virtual BakeStatus skipChunk(int level, int region) { return (void)level, (void)region, okStatus(); }
  // Bytes the sink has written so far (for PyramidLevelReport::stored_bytes; 0 if it writes none).
  virtual uint64_t storedBytes() const { return 0; }
};

// The sink of ndf-pyramid assets: level records as kSectionNdfLevel, chunks as kSectionNdfChunk
// sections of an open writer. Every level record must pass format::checkNdfLevelRecord against the
// level before it (kRuntime otherwise).
class WriterPyramidSink final : public PyramidSink {
 public:
  explicit WriterPyramidSink(format::Writer& writer) : writer_(writer) {}
  BakeStatus addLevel(const format::NdfLevelRecord& record) override;
  BakeStatus addChunk(const PyramidChunk& chunk) override;
  uint64_t storedBytes() const override { return writer_.bytesWritten(); }

 private:
  format::Writer& writer_;
  format::NdfLevelRecord below_;  // the last level added
};

// The sink of one shard of an ndf-pyramid bake: the sections WriterPyramidSink would write, at
// their positions in the asset, through a shard::PartialWriter: level records common to every
// shard, the chunks of the regions the shard computes, a skipped position for every other region.
class ShardPyramidSink final : public PyramidSink {
 public:
  explicit ShardPyramidSink(shard::PartialWriter& partial) : partial_(partial) {}
  BakeStatus addLevel(const format::NdfLevelRecord& record) override;
  BakeStatus addChunk(const PyramidChunk& chunk) override;
  BakeStatus skipChunk(int level, int region) override;

 private:
  shard::PartialWriter& partial_;
  format::NdfLevelRecord below_;
};

// Where a pyramid's images come from when they are not a normal map's flakes (procedural surfaces:
// libbake/glitter). image() writes the R x R NDF image (bin averages per unit s-plane area, row 0
// at s_y = +1; formats/SPEC.md section 9) of the footprint N((x, y), sigma^2), all in texels of a
// map of mapSize(). It is called concurrently from several threads and must give the same image
// whatever the thread.
class FootprintImageSource {
 public:
  virtual ~FootprintImageSource() = default;
  virtual void mapSize(int* width, int* height) const = 0;
  virtual void image(double x, double y, double sigma, float* out) const = 0;
  // How the level records say the surface continues beyond mapSize() (the runtime's blend wraps
  // the centre grid of a repeating surface and clamps to the edge centres of a clamped one).
  virtual Wrap wrap() const { return Wrap::kRepeat; }
};

// Builds the flakes of `map`, computes the pyramid and adds the level and chunk sections to an
// open writer (the caller adds metadata and calls finish()). Errors: kBadArgument (options),
// kRuntime (cancelled, out of memory), kIo (writer failure).
BakeStatus buildNdfPyramid(const NormalMap& map, const PyramidOptions& options, format::Writer& writer,
                           PyramidReport* report, const PyramidProgress& progress = {},
                           const std::atomic<bool>* cancel = nullptr);

// The same, streaming every level and chunk into `sink` instead (the builder's determinism holds:
// the sink sees identical data whatever the thread count). Errors: those above, plus whatever the
// sink returns.
BakeStatus buildNdfPyramid(const NormalMap& map, const PyramidOptions& options, PyramidSink& sink,
                           PyramidReport* report, const PyramidProgress& progress = {},
                           const std::atomic<bool>* cancel = nullptr);

// The same pyramid with every image from `source` (a surface of source.mapSize() texels that
// continues as source.wrap() says); options.rate and the splat's sigma_r are recorded in the level records only.
BakeStatus buildNdfPyramid(const FootprintImageSource& source, const PyramidOptions& options, PyramidSink& sink,
                           PyramidReport* report, const PyramidProgress& progress = {},
                           const std::atomic<bool>* cancel = nullptr);
BakeStatus buildNdfPyramid(const FootprintImageSource& source, const PyramidOptions& options, format::Writer& writer,
                           PyramidReport* report, const PyramidProgress& progress = {},
                           const std::atomic<bool>* cancel = nullptr);

}  // namespace glintbake::bake::ndf
