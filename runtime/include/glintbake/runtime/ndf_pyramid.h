// SPDX-License-Identifier: Apache-2.0
// Runtime-lite reader of ndf-pyramid assets (written by ndfgen): NDF images of Gaussian footprints
// on a multi-level grid of footprint centres (Deng et al. 2022, section 3), queried with the
// Gaussian footprint blend of formats/SPEC.md 10.1 (glintbake/format/kinds/ndf_pyramid_blend.h).
//
// Asset layout (formats/SPEC.md, "ndf-pyramid"):
//  - one kSectionNdfLevel section per level l (key = l) holding an NdfLevelRecord
//    (glintbake/format/kinds/ndf_pyramid.h, with its check);
//  - one kSectionNdfChunk section per level and spatial region (key = l << 32 | region, region =
//    ry * regions_x + rx) holding a format::ImageSectionHeader (width = height = R, channels = 1,
//    layers = centres in the region) and the region's images, centres in row-major order within the
//    region;
//  - level l: grid_width x grid_height centres; centre (i, j) at
//    (origin_x + i * stride_x, origin_y + j * stride_y) texels with origin = stride / 2, so the grid
//    covers the map exactly and each centre of level l + 1 is the centre of the 2 x 2 block of level
//    l centres it replaces whenever the grids nest (grid sizes even);
//  - footprint std of level l: sigma_texels = sigma0 * 2^l.
//
// Queries (Footprint in texels, SPoint in the s-plane):
//  - sigma <= sigma_0: the four nearest level-0 centres bilinearly; above, the Gaussian-weighted
//    mean of the centres of the finest level whose spread allows it (at most
//    format::kMaxBlendCentres images, of one or two levels); repeat maps wrap around the grid,
//    clamp maps clamp to the edge centres;
//  - every stored image is piecewise constant per bin, so the blend is too: eval(), average(),
//    sample() and pdf() are exactly consistent.
//
// Memory: all images are decompressed into memory by open() (R * R * 4 bytes per centre, plus
// (R + 1) * 8 bytes of row sums for sampling); e.g. a 1024^2 map at stride 16, R = 128 holds about
// 360 MB. Queries never allocate and are thread-safe (const). open() is safe on untrusted input:
// every size is checked against the container and against the descriptor before use.
#pragma once

#include <glintbake/format/kinds/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/pyramid_ndf.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

class NdfPyramid : public PyramidNdf {
 public:
  NdfPyramid();
  ~NdfPyramid() override;
  NdfPyramid(const NdfPyramid&) = delete;
  NdfPyramid& operator=(const NdfPyramid&) = delete;

  // open(), openMemory(), load(), isOpen(), levelCount(), level() and the argument checks of the
  // queries: pyramid_ndf.h. open() loads all images.
  format::AssetKind kind() const override { return format::AssetKind::kNdfPyramid; }

  // Stored image of centre (i, j) of level l (R * R floats), or null when out of range.
  const float* centreImage(int l, int i, int j) const;

 protected:
  RuntimeStatus loadKind(const format::Reader& reader) override;
  void reset() override;
  bool loaded() const override { return impl_ != nullptr; }
  const NdfLevelRecord* levelRecords(int* count) const override;
  format::NdfPyramidBlend* blender() override;
  const format::NdfPyramidBlend* blender() const override;

  // eval: value of the blended P-NDF at s (density per unit s-plane area; 0 outside [-1,1]^2).
  // average: exact average of the blended P-NDF over the rectangle (its parts outside [-1,1]^2
  // count as 0); cost grows with the number of bins the rectangle covers.
  // sample: s from the blended P-NDF; sample->pdf == pdf(footprint, s); kInvalidArgument if the
  // blend has no mass.
  // pdf: eval(s) divided by the blend's total mass (the mass is 1 to 1e-3 for footprints away from
  // the edges of clamp maps, so pdf == eval there).
  // mass: total mass of the blend (integral over the s-plane).
  // image: the blended image the runtime sees (R * R floats).
  RuntimeStatus evalChecked(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus averageChecked(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sampleChecked(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdfChecked(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus massChecked(const Footprint& footprint, double* value) const override;
  RuntimeStatus imageChecked(const Footprint& footprint, float* out) const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glintbake::runtime
