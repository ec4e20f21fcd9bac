// Runtime-lite reader of ndf-pyramid assets (written by ndfgen): NDF images of Gaussian footprints
// on a multi-level grid of footprint centres (Deng et al. 2022, section 3), queried with trilinear
// interpolation.
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
//  - level coordinate t = log2(sigma / sigma_0); sigma <= sigma_0 uses level 0 only, t >= top uses
//    the top level only, otherwise the two bracketing levels are blended linearly in t;
//  - on each level the four nearest centres are blended bilinearly; repeat maps wrap around the
//    grid, clamp maps clamp to the edge centres;
//  - every stored image is piecewise constant per bin, so the blend of up to 8 images is too:
//    eval(), average(), sample() and pdf() are exactly consistent.
//
// Memory: all images are decompressed into memory by open() (R * R * 4 bytes per centre, plus
// (R + 1) * 8 bytes of row sums for sampling); e.g. a 1024^2 map at stride 16, R = 128 holds about
// 360 MB. Queries never allocate and are thread-safe (const). open() is safe on untrusted input:
// every size is checked against the container and against the descriptor before use.
#pragma once

#include <glintbake/format/kinds/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

// The level descriptor is the container's record (formats/SPEC.md 10.1, kinds/ndf_pyramid.h).
using format::kMaxNdfLevels;
using format::NdfLevelRecord;

class NdfPyramid final : public NdfSource {
 public:
  NdfPyramid();
  ~NdfPyramid() override;
  NdfPyramid(const NdfPyramid&) = delete;
  NdfPyramid& operator=(const NdfPyramid&) = delete;

  // Loads an ndf-pyramid container (all images). kIoError, kInvalidAsset, kWrongKind,
  // kUnsupportedVersion, kOutOfMemory. Safe on untrusted input.
  Status open(const char* path);
  // Same, from a caller buffer (only needed during the call).
  Status openMemory(const void* data, size_t size);
  bool isOpen() const;

  int resolution() const override;  // R
  int levelCount() const;
  // Descriptor of level l in [0, levelCount()), or null.
  const NdfLevelRecord* level(int l) const;
  // Stored image of centre (i, j) of level l (R * R floats), or null when out of range.
  const float* centreImage(int l, int i, int j) const;

  // Value of the blended P-NDF at s (density per unit s-plane area; 0 outside [-1,1]^2).
  Status eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  // Exact average of the blended P-NDF over the rectangle (its parts outside [-1,1]^2 count as 0).
  // Cost grows with the number of bins the rectangle covers.
  Status average(const Footprint& footprint, const SRect& rect, double* value) const override;
  // Samples s from the blended P-NDF with two uniforms in [0, 1); sample->pdf == pdf(footprint, s).
  // kInvalidArgument if the blend has no mass.
  Status sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  // Density of sample(): eval(s) divided by the blend's total mass (the mass is 1 to 1e-3 for
  // footprints away from the edges of clamp maps, so pdf == eval there).
  Status pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  // Total mass of the blend (integral over the s-plane).
  Status mass(const Footprint& footprint, double* value) const override;
  // The blended image the runtime sees: out must hold R * R floats (out_count >= R * R).
  Status image(const Footprint& footprint, float* out, size_t out_count) const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glintbake::runtime
