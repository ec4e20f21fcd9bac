// SPDX-License-Identifier: Apache-2.0
// The query interface every NDF asset kind implements (ndf-pyramid, tensor-ndf, and the kinds that
// follow), so that a renderer or a tool can work with any of them through one pointer.
//
// All queries take a Gaussian pixel footprint (texels of the source normal map) and s-plane points
// or rectangles (runtime.h). Values are densities per unit s-plane area; an NDF of a footprint away
// from the edges of a clamped map integrates to 1 over [-1, 1]^2.
//
// Contract shared by every implementation:
//  - eval() >= 0 everywhere; 0 outside [-1, 1]^2;
//  - average() is the exact mean of the asset's piecewise-constant density over the rectangle
//    (parts outside [-1, 1]^2 count as 0);
//  - sample() returns a point together with the density with which it was drawn, and pdf() at that
//    point returns the same number (bit for bit);
//  - queries are const, thread-safe, never allocate and never throw; an invalid argument (non-finite
//    or negative sigma, non-finite s) returns kInvalidArgument and leaves outputs untouched. A sigma
//    of 0 is a point footprint: exact on assets with flakes (formats/SPEC.md 10.5), level 0 otherwise.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/runtime/runtime.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

// The footprint sizes (sigma, texels) an NDF source answers, and how. Pyramid-shaped assets blend
// their stored levels for sigma in [pyramid_min_sigma, pyramid_max_sigma]; above pyramid_max_sigma
// they clamp to the top level. Footprints with sigma <= exact_max_sigma are evaluated exactly
// (from stored flakes, or the reference evaluator); below pyramid_min_sigma and above
// exact_max_sigma an asset answers with its level 0 as is (a clamp: the NDF of a larger footprint).
struct FootprintRange {
  double pyramid_min_sigma = 0.0;  // sigma of level 0 (0: no pyramid)
  double pyramid_max_sigma = 0.0;  // sigma of the top level (0: no pyramid)
  double exact_max_sigma = 0.0;    // largest sigma answered exactly (0: no exact path)
  // Between exact_max_sigma and this the exact path and the pyramid are blended (linearly in
  // log sigma); from here on the pyramid answers alone (0: no hand-over band).
  double handover_max_sigma = 0.0;
  // Footprints answered by the clustered lobes (lobe_ndf.h) alone: [clustered_min_sigma,
  // clustered_max_sigma]; the exact path hands over to them across [exact_max_sigma,
  // clustered_min_sigma], and they to the pyramid across [clustered_max_sigma, handover_max_sigma].
  // Both 0: no clustered path.
  double clustered_min_sigma = 0.0;
  double clustered_max_sigma = 0.0;
};

// Texels of the source normal map, and how positions outside it are read (formats/SPEC.md 9).
struct MapSize {
  int width = 0;
  int height = 0;
};
enum class MapWrap : uint32_t {
  kRepeat = 0,  // the map tiles the plane
  kClamp = 1,   // positions outside the map read its edge
  // The source covers the whole plane without a period (Wang-tile grids, placed tiny examples):
  // callers pass surface positions as they are and never reduce them into one map; mapSize() is
  // then the size of one tile or example.
  kUnbounded = 2,
};

class NdfSource {
 public:
  virtual ~NdfSource() = default;

  // The container asset kind the source was read from (kUnknown for sources that are not assets).
  virtual format::AssetKind kind() const = 0;
  // Bins per side of the NDF images the asset represents.
  virtual int resolution() const = 0;
  // Which footprints the source answers and how (see FootprintRange).
  virtual FootprintRange footprintRange() const = 0;
  // Size of the source map in texels ({0, 0} when not open) and its wrap mode.
  virtual MapSize mapSize() const = 0;
  virtual MapWrap wrap() const = 0;

  virtual RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const = 0;
  virtual RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const = 0;
  // u1, u2 in [0, 1). kInvalidArgument when the footprint's NDF has no mass.
  virtual RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const = 0;
  virtual RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const = 0;
  // Integral of eval() over the s-plane.
  virtual RuntimeStatus mass(const Footprint& footprint, double* value) const = 0;
  // The R x R image of eval() (bin averages, row 0 at s_y = +1); out_count >= R * R.
  virtual RuntimeStatus image(const Footprint& footprint, float* out, size_t out_count) const = 0;

  // Pyramid-shaped sources: answer from the first level whose sigma is at least `sigma` (the top
  // level when none is) and never consult finer ones; footprints below that level's sigma get its
  // bilinear blend. The asset loader calls it before the source is shared, when the clustered
  // lobes stand in for the finer levels (their compression is not faithful); others ignore it.
  virtual void answerFromSigma(double sigma) { (void)sigma; }
};

// An NDF source whose image can be added, scaled, into a caller's buffer (the flakes and the
// clustered lobes), so that an asset blends two paths across a hand-over without a second buffer.
class AccumulatingNdfSource : public NdfSource {
 public:
  // Adds weight * image() to out (R * R floats); bins whose centre lies outside the unit disk are
  // left as they are.
  virtual RuntimeStatus addImage(const Footprint& footprint, double weight, float* out, size_t out_count) const = 0;
  // The R x R bins set to 0, then addImage() with weight 1.
  RuntimeStatus image(const Footprint& footprint, float* out, size_t out_count) const override {
    const size_t n = size_t(resolution()) * size_t(resolution());
    if (n == 0 || !out || out_count < n) return RuntimeStatus::kInvalidArgument;
    for (size_t i = 0; i < n; ++i) out[i] = 0.0f;
    return addImage(footprint, 1.0, out, out_count);
  }
};

// Opens any NDF asset kind the runtime knows (ndf-pyramid, tensor-ndf, glitter, wang-tiles),
// chosen by the container's
// asset kind. kIoError, kInvalidAsset, kWrongKind (a container of another kind), kUnsupportedVersion,
// kOutOfMemory. Safe on untrusted input. On failure *out is reset.
RuntimeStatus openNdfAsset(const char* path, std::unique_ptr<NdfSource>* out);
// Same, from a caller buffer (only needed during the call).
RuntimeStatus openNdfAssetMemory(const void* data, size_t size, std::unique_ptr<NdfSource>* out);

}  // namespace glintbake::runtime
