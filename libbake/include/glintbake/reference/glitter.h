// SPDX-License-Identifier: Apache-2.0
// Brute-force glitter (formats/SPEC.md 10.6): every facet of a small surface generated explicitly
// from the hierarchy down to its leaves, and the smooth distribution it converges to. The checks
// of the counting queries (format::glitterCount) against explicit enumeration.
#pragma once

#include <glintbake/format/kinds/glitter_model.h>

#include <cstdint>
#include <vector>

namespace glintbake::reference {

struct GlitterFacet {
  double u = 0.0, v = 0.0;     // position on the unit square
  format::GlitterVec3 normal;  // unit normal
  uint64_t leaf_code = 0;      // the leaf triangle holding it (depth = the surface's max_depth)
  int leaf_depth = 0;
};

// Every facet of the surface, as the tree shape's hierarchy generates them (N log N work and N x 40
// bytes: meant for N up to about 1e7). Ordered by the depth-first traversal of the hierarchy.
std::vector<GlitterFacet> enumerateGlitterFacets(const format::GlitterSurface& surface,
                                                 const format::GlitterTreeShape& shape);

// Facets inside uv region x direction region, one by one.
uint64_t countGlitterFacets(const std::vector<GlitterFacet>& facets, const format::GlitterUvRegion& uv,
                            const format::GlitterDirRegion& dir);

// The smooth limit: mean of D(h) cos(theta_h) over the cone of half-angle gamma around axis (the
// expected count divided by N x uvArea x 2 pi (1 - cos gamma)), by a 64 x 128 midpoint rule in the
// cone's polar coordinates.
double smoothGlitterCone(format::GlitterDistribution distribution, double alpha, const format::GlitterVec3& axis,
                         double gamma);

}  // namespace glintbake::reference
