// SPDX-License-Identifier: Apache-2.0
// Procedural glitter (discrete stochastic microfacets, Jakob et al. 2014) for the baker: the
// adaptive table of triangle integrals of the smooth NDF, the surface it defines
// (format::GlitterSurface, formats/SPEC.md 10.6), the glitter asset writer and the footprint
// image source that feeds the NDF pyramid builder (ndfgen --procedural glitter).
#pragma once

#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/result.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/glitter_model.h>

#include <cstdint>
#include <vector>

namespace glintbake::bake::glitter {

struct GlitterParams {
  uint64_t particles = 100000;  // N on the unit uv square, [1, format::kMaxGlitterParticles]
  double alpha = 0.2;           // [format::kMinGlitterAlpha, format::kMaxGlitterAlpha]
  format::GlitterDistribution distribution = format::GlitterDistribution::kBeckmann;
  uint64_t seed = 1;
  int max_depth = 20;                     // [1, 20]
  double gamma = 0.017453292519943295;    // radians (1 degree), (0, format::kMaxGlitterGamma]
  int map_width = 256, map_height = 256;  // texels the unit square spans, [1, 65536]
  int ndf_res = 64;                       // runtime image bins, [2, 4096]
};

// kBadArgument with a one-line message naming the first parameter out of range.
BakeStatus validateGlitterParams(const GlitterParams& params);

// Integrals of D cos over the spherical triangles of the direction hierarchy, tabulated
// adaptively: a triangle gets children while the sum of the centroid rules over its children
// differs from the centroid rule over it, or from the rule that adds its vertices (which sees a
// peak at a corner, such as the pole for small alpha), by more than tolerance (absolute, on a
// total of 1), down to
// max_depth levels and at most max_entries entries (breadth-first; formats/SPEC.md 10.6). A leaf
// holds the 16-point rule of its grandchildren; parents the sums of their children.
std::vector<format::GlitterIntegral> buildGlitterIntegrals(format::GlitterDistribution distribution, double alpha,
                                                           double tolerance = 1e-7, int max_depth = 10,
                                                           size_t max_entries = size_t(1) << 18);

// A surface with its own integral table (view() stays valid while the object lives and is not moved).
class GlitterModel {
 public:
  explicit GlitterModel(const GlitterParams& params);  // params must be valid
  const GlitterParams& params() const { return params_; }
  const format::GlitterSurface& view() const { return surface_; }
  const std::vector<format::GlitterIntegral>& integrals() const { return table_; }
  GlitterModel(const GlitterModel&) = delete;
  GlitterModel& operator=(const GlitterModel&) = delete;

 private:
  GlitterParams params_;
  std::vector<format::GlitterIntegral> table_;
  format::GlitterSurface surface_;
};

// The record of a surface with the given tree shape (the one shape every query of the asset uses).
format::GlitterRecord glitterRecord(const GlitterModel& model, const format::GlitterTreeShape& shape);
// The default tree shape of an asset: a box footprint of side sqrt(12) x sigma_texels (the box
// with the variance of that Gaussian) and the point-query cone of gamma.
format::GlitterTreeShape defaultGlitterShape(const GlitterParams& params, double sigma_texels);

// Adds the glitter-info and glitter-integrals sections to an open writer of kind glitter.
BakeStatus writeGlitterSections(format::Writer& writer, const GlitterModel& model,
                                const format::GlitterTreeShape& shape);

// The NDF images of a glitter surface for the pyramid builder: footprint-weighted facets binned by
// their normals (format::glitterBinnedWeights), divided by N and the bin area. One tree shape for
// every image (a box of the level-0 footprint, and one bin's solid angle as the cone), so that
// every centre and level sees the same facets.
class GlitterImageSource final : public ndf::FootprintImageSource {
 public:
  GlitterImageSource(const GlitterModel& model, int ndf_res, double sigma0_texels);
  void mapSize(int* width, int* height) const override;
  void image(double x, double y, double sigma, float* out) const override;
  const format::GlitterTreeShape& shape() const { return shape_; }

 private:
  const GlitterModel& model_;
  int res_;
  format::GlitterTreeShape shape_;
};

}  // namespace glintbake::bake::glitter
