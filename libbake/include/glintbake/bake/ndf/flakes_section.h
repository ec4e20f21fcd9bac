// SPDX-License-Identifier: Apache-2.0
// The flakes section of NDF assets (formats/SPEC.md 10.5): the normal map a pyramid is baked from,
// at float32 precision, so that the runtime answers small footprints exactly from its flakes
// (Yan et al. 2016) and hands over to the pyramid above them.
#pragma once

#include <vector>

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/result.h>
#include <glintbake/format/container.h>
#include <glintbake/runtime/texel_source.h>

#include <cstdint>
#include <functional>

namespace glintbake::bake::ndf {

// Footprints (std, texels) the flakes answer alone, the clustered lobes alone (from sqrt(2) x
// flakes_up_to to lobes_up_to) and the pyramid alone (from pyramid_from); neighbouring paths are
// blended linearly in log(sigma) in between. lobes_per_tile 0: no clustered path, the flakes hand
// over to the pyramid directly.
// tile_ratio_milli: the clustered path's tile ratio in thousandths (formats/SPEC.md 10.5, the
// record's trailer); 0 lets chooseLobeTileRatio pick it for the map and this hand-over.
struct FlakesHandover {
  double flakes_up_to = 0.0;
  int lobes_per_tile = 0;
  double lobes_up_to = 0.0;
  double pyramid_from = 0.0;
  uint32_t tile_ratio_milli = 0;
};

// The tile ratios (thousandths) chooseLobeTileRatio tries, largest (cheapest) first: the default,
// then finer tiles at about twice and four times the clustered path's eval cost.
constexpr uint32_t kLobeTileRatioCandidates[] = {350, 250, 175};

// The clustered path's tile ratio for a map and hand-over (formats/SPEC.md 10.5, the record's
// trailer): the largest candidate whose lobes stay close to the exact flakes at the probe
// footprints the lobes answer (kLobeProbeSigmas below pyramid_from, within the lobes' and the
// exact flakes' windows and below the flat footprint of a repeating map), measured as the targets
// of scripts/fidelity.py are, with margins: at kLobeProbePositions positions each, the relative L1
// distance of the lobes' NDF from the exact flakes' must have a median of at most
// kLobeProbeMaxError and of at most kLobeProbeMaxRatio times that of the positions' mean NDF (a
// stand-in for the whole map's, the smooth baseline). Distances are estimated from
// kLobeProbeSamples points of either NDF at each position, of densities whose lobes are widened
// by the variance of a bin of an R = kLobeProbeResolution image (the images the targets are on
// average detail finer than a bin out). Maps whose tiles hold more distinct normals than a tile
// keeps lobes (dense fine scratches, small flakes) get finer tiles; maps whose NDF varies strongly
// across them, or whose pyramid answers from below the probes, keep the default. When no candidate
// passes, the finest. Without lobes (lobes_per_tile 0) or probes, the default. Deterministic for any
// thread count. A map of more than max_probe_flakes flakes is probed on a window at its centre of
// at most sqrt(max_probe_flakes) flakes per side (sides and origin whole multiples of
// kLobeProbeCropAlign texels, so that its tiles are the map's; clamped): the probe's memory (about
// 140 bytes a flake) and time (a few seconds) stay those of a 2048^2 map whatever the map's size.
constexpr double kLobeProbeSigmas[] = {24.0, 32.0, 48.0};
constexpr int kLobeProbePositions = 6;
constexpr int kLobeProbeSamples = 32;
constexpr int kLobeProbeResolution = 128;
constexpr double kLobeProbeMaxError = 0.08;
constexpr double kLobeProbeMaxRatio = 0.2;
constexpr uint64_t kLobeProbeMaxFlakes = uint64_t(2048) * 2048;
constexpr int kLobeProbeCropAlign = 128;
uint32_t chooseLobeTileRatio(const runtime::TexelSource& texels, int rate, double sigma_r, int lobes_per_tile,
                             double pyramid_from, uint64_t max_probe_flakes = kLobeProbeMaxFlakes);

// Lobes per tile of the clustered path: the default and the largest (formats/SPEC.md 10.5).
constexpr int kDefaultLobesPerTile = 16;
constexpr int kMaxLobesPerTile = 16;

// `handover` on a map of that size: on a repeating map a footprint of std F = kFlatAxisSigma (0.62)
// times its longer side weighs every texel alike (ripple 1e-3), and from there the pyramid, whose
// levels are flat over the map once that wide (levelGeometry), answers with the whole map's NDF
// where the lobes of a map a few tiles across are coarser (a 9 x 6 map at 12 texels: 0.05 relative
// L1 against 0.000). So the pyramid answers alone from F and the lobes up to F / sqrt(2) (at least
// 4 sqrt(2)) when the hand-over's bounds are higher; unchanged when the lobes answer every
// footprint (no faithful level). fitHandoverToMap applies it to repeating maps.
FlakesHandover capAtFlatFootprint(const FlakesHandover& handover, int map_width, int map_height, bool repeat);

// Clamped maps of at most this many flakes (texels x rate^2) are answered by their flakes alone up
// to kClampedFlatSigma (2) times their longer side, where a footprint's weights are within 3% of
// flat over the map: an exact query then costs at most this many flakes whatever the footprint
// (a clamped map has no flakes beyond its edges), within a pyramid query's budget, where the
// pyramid of a map a few dozen texels across has one centre per level (a 37 x 23 map at 24
// texels: 0.17 relative L1 against the reference).
constexpr uint64_t kSmallClampedMapFlakes = 4096;

// `handover` fitted to a map of that size, wrap and rate (flakes per texel side): on a repeating
// map capAtFlatFootprint; on a clamped one of at most kSmallClampedMapFlakes flakes whose window
// at that footprint fits runtime::kMaxFlakeWindow, the flakes answer alone up to F =
// kClampedFlatSigma x the longer side (no clustered lobes) and hand over to the pyramid across the
// half octave above F, when the given hand-over's flakes stop below F; unchanged otherwise.
// flakesSectionBytes and setFlakesHandover record it so fitted.
FlakesHandover fitHandoverToMap(const FlakesHandover& handover, int map_width, int map_height, bool repeat, int rate);

// The hand-over for a pyramid whose finest level has footprint std sigma0 (texels) and is faithful
// from there on (an uncompressed pyramid). With lobes (1..16 per tile): the flakes answer up to 4
// texels, the lobes from 4 sqrt(2) to sqrt(2) sigma0 (between the centres of its finest level the
// pyramid blends images, a few percent off), and the pyramid alone from 2 sigma0. Without (lobes_per_tile 0): the
// flakes answer up to max(4, sigma0) and the pyramid takes over across a half octave above that.
FlakesHandover defaultHandover(double sigma0, int lobes_per_tile);

// The hand-over for a compressed pyramid: level_sigmas[l] is the footprint std of level l and
// level_errors[l] the relative error of its compression. The pyramid answers from the first level
// from which every level's error is at most max_level_error, as defaultHandover places it above
// an uncompressed finest level; the lobes answer below it, down to 4 sqrt(2) texels. When no such
// level exists the lobes answer every footprint they can (the runtime bounds them by their window)
// and the pyramid only above. When that first level is stored exactly (level_exact[l], may be
// null), the lobes answer up to its sigma and the pyramid alone from sqrt(2) times it, unless
// blend_loses (may be empty) says that the lobes should answer above it instead
// (HandoverProbe::lobesAnswer): then it is asked for the levels above in turn, and the lobes answer
// up to sqrt(2) times the last level it says so of (the pyramid alone from twice it, as above a
// compressed level). It is asked only for that first level and the levels above it, in order.
FlakesHandover compressedHandover(const double* level_sigmas, const double* level_errors, int levels,
                                  double max_level_error, int lobes_per_tile, const bool* level_exact = nullptr,
                                  const std::function<bool(int level)>& blend_loses = {});

// The shape of one pyramid level, for probeExactLevelHandover: its footprint std (texels) and its
// grid of centres over the map (formats/SPEC.md 10.1: strides map size / grid, origins half a stride).
struct PyramidLevelShape {
  double sigma = 0.0;
  int grid_width = 0, grid_height = 0;
};

// What probeExactLevelHandover measured at footprint std `sigma`: the median relative L1 against
// the exact flakes of the pyramid's blend and of the clustered lobes, and of the smooth baseline;
// ran is false when the lobes cannot answer there (beyond their window or the exact flakes', or
// beyond the footprint from which a repeating map's pyramid answers alone, capAtFlatFootprint).
// The pyramid costs a tenth of the lobes' time there (README, "Figures"), so it answers wherever
// its blend is faithful, within kHandoverBlendMaxError and kHandoverBlendMaxRatio times the
// baseline (the lobes' own probe allows 0.08 and 0.2: the blend is measured at the sigma where the
// two hand-overs differ most, and keeps a wider margin for the positions the probe does not see),
// and wherever the lobes are no closer; elsewhere the lobes answer.
constexpr double kHandoverBlendMaxError = 0.04;
constexpr double kHandoverBlendMaxRatio = 0.2;
struct HandoverProbe {
  bool ran = false;
  double sigma = 0.0;
  double blend_error = 0.0;
  double lobes_error = 0.0;
  double baseline = 0.0;
  bool lobesAnswer() const {
    const bool faithful = blend_error <= kHandoverBlendMaxError && blend_error <= kHandoverBlendMaxRatio * baseline;
    return ran && !faithful && lobes_error < blend_error;
  }
};

// Above an exact level the pyramid blends the stored images of its centres (and, as the spread
// grows, of the next level's); the clustered lobes could answer there instead. Which is closer
// depends on the map, not on how much its images vary: where a footprint holds many similar
// texels the blend's small error in each centre's weight averages out (bumps, fine scratches,
// brushed and rough isotropic maps), where a few glints dominate (sharp flakes, leather) it does
// not. So it is measured, on the map: at
// kHandoverProbePositions positions (a golden-ratio sequence over the map) at footprint std sigma
// (sqrt(2) times the level probed: where the two hand-overs compressedHandover chooses between
// differ most), the
// relative L1 of R = kLobeProbeResolution NDF images against the splat of the footprint (the
// reference scripts/fidelity.py uses at these sizes), of
//  - the pyramid's answer: format::NdfPyramidBlend's weights over `levels` (levels[0] the finest
//    level the pyramid answers from, the first exact one, then those above it; the runtime's blend
//    takes the finest of them whose spread allows it) applied to the splats of the centres' level footprints (with the
//    levels' footprint partition on repeating maps: what an exact level stores), and
//  - the lobes' at the default tile ratio;
// and the baseline: each position's image against the mean of all of them.
// Maps of more than max_probe_flakes flakes are probed on the window chooseLobeTileRatio uses,
// with the levels' strides kept (rounded to tile the window). Deterministic.
constexpr int kHandoverProbePositions = 8;
HandoverProbe probeExactLevelHandover(const runtime::TexelSource& texels, int rate, double sigma_r, int lobes_per_tile,
                                      const PyramidLevelShape* levels, int count, double sigma,
                                      uint64_t max_probe_flakes = kLobeProbeMaxFlakes);

// Appends the flakes section (key 0) to a container: the map's (n_x, n_y) as float32, its wrap
// mode, rate (1..16) and sigma_r, the hand-over, and (with lobes) the tile ratio
// chooseLobeTileRatio picks for the map. The record is checked by
// format::checkFlakesRecord before it is written. *bytes (may be null) receives the raw section size.
// Errors: kBadArgument (a record the check refuses: map too large, rate, sigma_r or hand-over out of
// range), kIo (the writer failed).
BakeStatus writeFlakesSection(format::Writer& writer, const NormalMap& map, int rate, double sigma_r,
                              const FlakesHandover& handover, uint64_t* bytes);
// The raw bytes of that section (record, normals and trailer), for writers that place it themselves
// (sharded bakes). Same errors, kIo aside.
Result<std::vector<uint8_t>> flakesSectionBytes(const NormalMap& map, int rate, double sigma_r,
                                                const FlakesHandover& handover);

// Rewrites the hand-over of a flakes section's record in place (a version-1 record becomes version
// 2; the tile ratio of a version-3 trailer is kept), as flakesSectionBytes would have written it
// with `handover`: tools whose hand-over depends
// on the finished pyramid (tensorpack, and the merge of its shards) write the section through this.
// kInvalidInput when the section is truncated or the record fails format::checkFlakesRecord.
BakeStatus setFlakesHandover(std::vector<uint8_t>& section, const FlakesHandover& handover);

}  // namespace glintbake::bake::ndf
