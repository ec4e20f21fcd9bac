// SPDX-License-Identifier: Apache-2.0
// Packs a footprint pyramid of NDF images into a tensor-ndf asset (formats/SPEC.md section 10.4):
// every image is cut into B x B angular blocks, the non-blank blocks of all centres of one region
// of one level are stacked into a B x B x K group tensor, and each group is stored as a rank-R CP
// model with per-block prefix sums of A and B (Deng et al. 2022, "Constant-Cost
// Spatio-Angular Prefiltering of Glinty Appearance Using Tensor Decomposition", ACM TOG, sec. 4), so that a renderer
// evaluates any bin range of any block in O(R).
//
// Streaming: the pyramid is consumed one region at a time (straight from the builder, or one chunk
// at a time from an ndf-pyramid container); a region's blocks are copied into its group tensor and
// the group is decomposed as a TBB task while the builder computes the next regions, so peak
// memory is bounded by the tensors of the groups in flight (at most threads + 1 of them, each at
// most region_size^2 * R^2 floats, 16 MiB at the defaults) and one level's index (8 bytes per
// block), never the whole pyramid.
//
// Section order (fixed, whatever the thread count): for each level, its ndf-level record, the
// tensor-group sections of its regions in region order (group ids 0, 1, ... in write order:
// level-major, then region order; regions whose blocks are all blank have no group), then its
// tensor-index; after the last level, the tensor-info record. The caller adds the metadata and
// finishes the writer.
//
// Blank blocks: a block whose mass (the integral of its density over its s-plane area, in [0, 1]
// for a normalised NDF image) is below blank_threshold is dropped: its index entry says "blank"
// and it reconstructs to 0. All-zero blocks (e.g. outside the unit disk) always go. The default
// 1e-5 bounds the mass lost per image by nb^2 * 1e-5 (1.6e-4 at R = 128, B = 32); README.md,
// "Figures", compares thresholds.
//
// Stored factors: the CP columns are rebalanced so that A, B and C columns have equal norms (the
// product is unchanged); this keeps float16 factors far from overflow and underflow. Prefix sums
// are computed in double from the stored (rounded) factor values and rounded to float32 once.
//
// Dead columns: when a kCompressed or kAls decomposition returns rank-1 terms that vanish (their
// deterministic HOSVD start stalls when a mode unfolding of the group has lower rank than R, e.g.
// the few repeated spike patterns of a flat map, whose lobes are narrower than a bin: relative
// error 0.71 at every rank <= B), the group is decomposed again from kAlsPlain's seeded random
// start at the same rank and the better fit is kept. Groups without vanishing terms pay nothing.
//
// Errors: a factor that is not finite after decomposition or storage rounding fails with kRuntime.
// Determinism: output bytes depend only on the pyramid and the options (never on `threads`, timing
// or scheduling): each group's CP is sequential and seeded, sections are written in a fixed order.
// Thread safety: the functions are reentrant; they use TBB internally (threads > 0 limits them).
// Untrusted input: packTensorNdfFromPyramid checks every record, size and value of the container
// it reads (kInvalidInput on anything inconsistent or non-finite).
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/result.h>
#include <glintbake/bake/tensor/cp_decomposition.h>
#include <glintbake/format/binary16.h>
#include <glintbake/format/container.h>

#include <atomic>
#include <cstdint>
#include <map>
#include <vector>

namespace glintbake::bake::tensor {

constexpr double kDefaultBlankThreshold = 1e-5;

constexpr uint64_t kMaxExactCentres = 256;
constexpr uint64_t kExactAnyLevelCentres = 4;

struct TensorPackOptions {
  CpOptions cp;    // rank (default 16) is the rank, or the largest rank of error-target mode
  int block = 32;  // B: bins per block side, divides the NDF resolution, [1, kMaxBlockBins]
  double blank_threshold = kDefaultBlankThreshold;  // block mass below this is dropped, [0, 1]
  double error_target = -1.0;  // < 0: fixed rank; else per group the smallest rank <= cp.rank whose
                               // relative error is <= error_target, [0, 1]
  int precision = 0;           // factor storage: 0 float32, 1 float16
  int threads = 0;             // TBB workers, 0 = all cores (the tool's -j)
  // Levels whose NDF images take at most this many bytes (float32, R^2 * 4 per centre) are stored
  // exactly instead of compressed: every kept block its own group of rank B with the identity as
  // A (4 B^2 + 4 B values a block on load, about four times the images). The coarse levels are
  // small and CP keeps little of their glints at rank 16 (README, "Figures"). 0: none; needs
  // B <= 64.
  // At most kMaxExactCentres (16 x 16) centres per exact level: the runtime reads exact blocks
  // directly (cp_block.h), and a footprint blends at most kMaxBlendCentres of them.
  uint64_t exact_level_bytes = 0;
  // ... and whose index is at least this: finer levels stay compressed (tensorpack sets 1: the
  // clustered lobes answer level 0's footprints from single flakes), except levels of at most
  // kExactAnyLevelCentres centres of a repeating map (a map of a few dozen texels per side, whose
  // level 0 may be its only level and then answers every footprint wider than the map: on a 9 x 6
  // map rank 16 kept its one image at relative L1 0.46).
  int exact_min_level = 0;
};

// Validates ranges (kBadArgument naming the option, as the tool spells it).
BakeStatus validateTensorPackOptions(const TensorPackOptions& options);

struct TensorPackLevelReport {
  int level = 0;
  int grid_width = 0, grid_height = 0;
  double sigma = 0.0;  // footprint std of the level, texels
  uint64_t groups = 0;
  uint64_t blocks_kept = 0;
  uint64_t blocks_dropped = 0;
  uint64_t raw_bytes = 0;       // float32 bytes of the level's NDF images (R^2 * 4 per centre)
  uint64_t stored_bytes = 0;    // bytes the level's group and index sections add to the file
  double relative_error = 0.0;  // |D - model|_F / |D|_F over every bin of the level (dropped blocks included)
  double error_squared = 0.0;   // |D - model|_F^2
  double norm_squared = 0.0;    // |D|_F^2
  // sum |D - model| / sum |D| over every bin of the level (dropped blocks included): the mean
  // relative L1 error of its NDF images, the measure the fidelity targets use. CP spreads a
  // little mass over many bins, which the Frobenius error (dominated by the peaks) hardly sees.
  double l1_error = 0.0;
  double error_l1 = 0.0, data_l1 = 0.0;  // sum |D - model| over the kept blocks, and sum |D| over them
  // |D - mean image|_F / |D|_F: how far the level's images stand from their mean (what a single
  // smooth image per level would miss). A compression error well below it keeps the glints.
  double variation = 0.0;
  bool exact = false;  // stored exactly (TensorPackOptions::exact_level_bytes)
};

struct TensorPackReport {
  int ndf_res = 0;          // R of the pyramid's images
  int blocks_per_side = 0;  // R / B
  std::vector<TensorPackLevelReport> levels;
  uint64_t groups = 0;
  uint64_t blocks_kept = 0;
  uint64_t blocks_dropped = 0;
  uint64_t raw_bytes = 0;                  // float32 bytes of all NDF images
  uint64_t stored_bytes = 0;               // bytes of all sections added (before the caller's metadata/index)
  double relative_error = 0.0;             // over the whole pyramid
  double max_group_error = 0.0;            // largest relative error of one group (kept blocks only)
  double negative_mass_fraction = 0.0;     // sum of max(0, -model) over kept blocks / sum of |model|
  std::map<int, uint64_t> rank_histogram;  // rank -> groups
  int max_rank = 0;
  ndf::PyramidReport pyramid;  // from-map only: the builder's report (levels, stop reason, flakes)
  double ndf_seconds = 0.0;    // wall time producing NDF images (splatting, or reading chunks)
  double cp_seconds = 0.0;     // summed time of the CP tasks (they run in parallel: may exceed wall time)
  double write_seconds = 0.0;  // time adding sections to the writer (compression + I/O)
  double wait_seconds = 0.0;   // time the producer waited for CP tasks to finish
  double total_seconds = 0.0;  // wall time of the call
};

// From a normal map: the pyramid is generated region by region (ndf::buildNdfPyramid with a sink)
// and each region's group is compressed as it comes; the raw pyramid is never held. Adds every
// section of the asset except the metadata. `progress` is the builder's (per chunk). Errors:
// kBadArgument (options), kInvalidInput (every block of the pyramid blank), kRuntime (cancelled,
// CP failure, out of memory), kIo (writer failure).
BakeStatus packTensorNdfFromMap(const NormalMap& map, const ndf::PyramidOptions& pyramid,
                                const TensorPackOptions& options, format::Writer& writer, TensorPackReport* report,
                                const ndf::PyramidProgress& progress = {}, const std::atomic<bool>* cancel = nullptr);

// The same into any TensorRegionConsumer (tensor_assembly.h) instead of a writer: a sharded bake
// passes pyramid.region_filter and a consumer that records its regions' results (the regions the
// filter refuses reach it as skipRegion). The consumer is not finished; the report holds timings
// and the pyramid's report only.
class TensorRegionConsumer;
BakeStatus packTensorNdfFromMap(const NormalMap& map, const ndf::PyramidOptions& pyramid,
                                const TensorPackOptions& options, TensorRegionConsumer& consumer,
                                TensorPackReport* report, const ndf::PyramidProgress& progress = {},
                                const std::atomic<bool>* cancel = nullptr);

// The same from a procedural source of NDF images (ndf::FootprintImageSource, e.g. glitter).
BakeStatus packTensorNdfFromSource(const ndf::FootprintImageSource& source, const ndf::PyramidOptions& pyramid,
                                   const TensorPackOptions& options, format::Writer& writer, TensorPackReport* report,
                                   const ndf::PyramidProgress& progress = {},
                                   const std::atomic<bool>* cancel = nullptr);

// From an ndf-pyramid container (reads one chunk at a time). The output is byte-identical to
// packTensorNdfFromMap with the pyramid options that built the container. Errors: as above, plus
// kInvalidInput for a container that is not a valid ndf-pyramid and kIo for read failures.
BakeStatus packTensorNdfFromPyramid(const format::Reader& pyramid, const TensorPackOptions& options,
                                    format::Writer& writer, TensorPackReport* report,
                                    const std::atomic<bool>* cancel = nullptr);

// IEEE 754 binary16 conversion (the container library's codec, glintbake/format/binary16.h).
using format::floatToHalf;
using format::halfToFloat;

}  // namespace glintbake::bake::tensor
