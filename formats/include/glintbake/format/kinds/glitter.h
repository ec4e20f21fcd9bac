// SPDX-License-Identifier: Apache-2.0
// The glitter asset kind (formats/SPEC.md 10.6): a procedural surface of N discrete microfacets
// (Jakob et al. 2014, "Discrete Stochastic Microfacet Models") defined by a handful of numbers and
// the cached integrals of its smooth NDF over the spherical triangles of the direction hierarchy.
// The records and their checks; the model itself (hierarchy, draws, queries) is glitter_model.h.
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

// The smooth distribution the facet normals are drawn from: the pdf of a normal h per unit solid
// angle is D(h) cos(theta_h), with D the Beckmann or GGX NDF of roughness alpha.
enum class GlitterDistribution : uint32_t {
  kBeckmann = 0,
  kGgx = 1,
};
const char* glitterDistributionString(GlitterDistribution d);  // "beckmann", "ggx"; "unknown" otherwise

// Section kSectionGlitterInfo (key 0, exactly one), 64 bytes little-endian.
struct GlitterRecord {
  uint32_t magic = 0x544C4747;  // "GGLT"
  uint32_t version = 1;
  uint32_t distribution = 0;  // GlitterDistribution
  uint32_t max_depth = 20;    // levels of the uv quadtree and of the triangle hierarchy, 1..20
  uint64_t particles = 0;     // N facets on the unit uv square, 1..kMaxGlitterParticles
  uint64_t seed = 0;          // any value: selects the realisation
  double alpha = 0.0;         // roughness of the smooth NDF, [kMinGlitterAlpha, kMaxGlitterAlpha]
  double gamma = 0.0;         // radians, half-angle of the direction cone of point queries, (0, kMaxGlitterGamma]
  uint32_t map_width = 0;     // texels the unit uv square spans (footprints of NdfSource queries are in texels)
  uint32_t map_height = 0;
  uint32_t ndf_res = 0;         // bins per side of the images the runtime makes (2..4096)
  uint32_t integral_count = 0;  // entries of the kSectionGlitterIntegrals table, 4..kMaxGlitterIntegrals
  double shape_area = 0.0;      // tree shape of every query on the asset: uv area, (0, 1]
  double shape_cone = 0.0;      // and solid angle (sr), (0, 2 pi]; see GlitterTreeShape
};
static_assert(sizeof(GlitterRecord) == 80, "GlitterRecord is 80 bytes");

// One entry of the kSectionGlitterIntegrals table (key 0): the integral of D(h) cos(theta_h) over
// one spherical triangle of the direction hierarchy, and the index of its first child (its four
// children are consecutive) or 0 for a triangle whose children are not tabulated. Entries 0..3 are
// the root triangles; children appear in breadth-first order, so the first child indices of the
// entries that have children are 4, 8, 12, ... in entry order.
struct GlitterIntegral {
  double integral = 0.0;
  uint32_t first_child = 0;
  uint32_t reserved = 0;
};
static_assert(sizeof(GlitterIntegral) == 16, "GlitterIntegral is 16 bytes");

constexpr uint64_t kMaxGlitterParticles = uint64_t(1) << 40;
constexpr double kMinGlitterAlpha = 1e-3;
constexpr double kMaxGlitterAlpha = 4.0;
constexpr double kMaxGlitterGamma = 0.5;  // radians (about 28.6 degrees)
constexpr uint32_t kMaxGlitterDepth = 20;
constexpr uint32_t kMaxGlitterIntegrals = 1u << 20;
constexpr uint32_t kMaxGlitterMapSide = 1u << 16;

// Checks every field of a glitter record against SPEC.md 10.6 (null when valid, otherwise a short
// message naming the first offending field). Safe on untrusted input.
const char* checkGlitterRecord(const GlitterRecord& record);

// Checks an integral table (count entries) against SPEC.md 10.6: the breadth-first child layout,
// finite non-negative values, every tabulated parent equal to the sum of its children (relative
// 1e-6) and the roots summing to 1 within 1e-3. Null when valid. Safe on untrusted input.
const char* checkGlitterIntegrals(const GlitterIntegral* table, size_t count);

// Checks the section layout of a glitter asset against SPEC.md 10.6: exactly one glitter-info
// section and one glitter-integrals section, given how many of each the container holds. Null when
// it fits, otherwise which of the two is not there exactly once.
const char* checkGlitterLayout(size_t info_sections, size_t integral_sections);

}  // namespace glintbake::format
