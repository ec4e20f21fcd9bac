// SPDX-License-Identifier: Apache-2.0
// Runtime-lite reader of glitter assets (formats/SPEC.md 10.6): a procedural surface of N discrete
// microfacets (Jakob et al. 2014) answering NDF queries through NdfSource, with no stored facets.
//
// A footprint N((x, y), sigma^2) in texels of the asset's map size weighs every facet by the
// normalised Gaussian on the periodic unit square (format::glitterWeightedCount). With W the
// footprint's weighted facets and n_s = N / (map_width map_height) the facets per texel:
//  - eval(s): the weighted facets within gamma (the record's cone) of h = (s, sqrt(1 - |s|^2)), plus
//    those within gamma of its mirror image below the horizon, / (N x 2 pi (1 - cos gamma) x h_z)
//    (weights are per unit uv area): a density per unit s-plane area, 0 for |s| >= 1;
//  - mass(): W / N (about 1: the facets are a Poisson-like sample of the smooth NDF);
//  - sample(): a facet drawn with probability proportional to its weight, then a direction
//    uniform in its cone (mirrored above the horizon); pdf() = eval() / mass(), and the sample's
//    pdf is pdf() at the sampled point, bit for bit;
//  - image() and average(): the weighted facets binned by their normals instead of cones (the
//    bins of formats/SPEC.md section 9), as ndfgen --procedural glitter bakes them; average over a
//    rectangle = weighted facets with (h_x, h_y) in it / (N x its area).
// Every query uses the record's tree shape, so all footprints see the same facets. Cost grows
// with log N and with the facets the footprint holds (bench/bench_glitter.cpp); sample() costs
// about two weighted counts. Queries are const, thread-safe and never allocate. load() is safe on
// untrusted input (the record and the integral table are checked before use).
#pragma once

#include <glintbake/format/kinds/glitter_model.h>
#include <glintbake/runtime/ndf_source.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

class GlitterNdf final : public NdfSource {
 public:
  GlitterNdf() = default;
  GlitterNdf(const GlitterNdf&) = delete;
  GlitterNdf& operator=(const GlitterNdf&) = delete;

  // kIoError, kInvalidAsset, kWrongKind, kUnsupportedVersion, kOutOfMemory.
  RuntimeStatus open(const char* path);
  RuntimeStatus openMemory(const void* data, size_t size);
  RuntimeStatus load(const format::Reader& reader);
  bool isOpen() const { return open_; }

  const format::GlitterRecord& record() const { return record_; }
  const format::GlitterSurface& surface() const { return surface_; }
  format::GlitterTreeShape shape() const { return {record_.shape_area, record_.shape_cone}; }
  // The footprint in the unit square's coordinates (sigma clamped to [1e-4, 4 x map side] texels).
  format::GlitterGaussian gaussian(const Footprint& footprint) const;

  format::AssetKind kind() const override { return format::AssetKind::kGlitter; }
  int resolution() const override { return open_ ? int(record_.ndf_res) : 0; }
  FootprintRange footprintRange() const override;
  MapSize mapSize() const override;
  MapWrap wrap() const override { return MapWrap::kRepeat; }

  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus mass(const Footprint& footprint, double* value) const override;
  RuntimeStatus image(const Footprint& footprint, float* out, size_t out_count) const override;

 private:
  bool validFootprint(const Footprint& f) const;
  double coneWeight(const format::GlitterGaussian& g, const SPoint& s) const;

  bool open_ = false;
  format::GlitterRecord record_;
  std::unique_ptr<format::GlitterIntegral[]> table_;
  format::GlitterSurface surface_;
};

}  // namespace glintbake::runtime
