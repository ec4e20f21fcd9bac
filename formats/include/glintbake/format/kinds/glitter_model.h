// SPDX-License-Identifier: Apache-2.0
// The discrete stochastic microfacet surface of glitter assets (formats/SPEC.md 10.6; Jakob et al.
// 2014): N facets on the unit uv square whose normals follow D(h) cos(theta_h), never stored but
// generated on demand by a counting hierarchy. The one implementation used by the runtime's
// glitter asset, the baker (ndfgen --procedural glitter) and glintref, as the pyramid blend is.
//
// Hierarchy. A node is a uv cell of the quadtree over [0,1)^2 (level a, column ix, row iy) times a
// direction node: the hemisphere (depth 0) or a spherical triangle (depth b >= 1; the four roots
// have the vertices z, +-x, +-y, and the children of a triangle come from its normalised edge
// midpoints). Each node holds a particle count n; the root holds N. A node is split either in
// space (four uv children, probability 1/4 each) or in direction (four triangles, probabilities
// proportional to the integrals of D cos over them), by the paper's rule evaluated with a fixed
// tree shape (GlitterTreeShape): split space when shape.cone / 4 * uvArea > shape.area * dirArea,
// else direction; a dimension at max_depth is never split again. The counts of the children are a
// multinomial draw seeded by a hash of the node (exact categorical draws for n < 8, otherwise the
// Gaussian approximation with mean n p and covariance n (diag p - p p^T), rounded and repaired to
// sum to n). A node's count is therefore a function of the node and the tree shape alone: every
// query of one shape sees the same facets, and the counts of disjoint regions add up.
//
// Leaves (both dimensions at max_depth) hold explicit facets: facet k sits at a position drawn
// uniformly in the cell from the node's hash, with the normalised centroid of the leaf triangle as
// its normal.
//
// Direction split probabilities come from the integral table (GlitterIntegral, tabulated
// adaptively by the baker); below the tabulated triangles, from the centroid rule D cos(centroid)
// x solid angle of each child, normalised over the four.
//
// Everything here is header-declared, allocation-free and thread-safe; the traversals recurse at
// most 2 * max_depth + 1 levels.
#pragma once

#include <glintbake/format/kinds/glitter.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

struct GlitterVec3 {
  double x = 0.0, y = 0.0, z = 0.0;
};

// D(h) cos(theta_h) of the distribution for a unit vector h (0 for h.z <= 0); integrates to 1 over
// the hemisphere.
double glitterNdfCos(GlitterDistribution d, double alpha, const GlitterVec3& h);
// Solid angle of the spherical triangle (a, b, c) of unit vectors (Van Oosterom and Strackee).
double sphericalTriangleArea(const GlitterVec3& a, const GlitterVec3& b, const GlitterVec3& c);
// Vertices of root triangle r (0..3) and of child j (0..3: corners at v0, v1, v2, then the middle)
// of a triangle.
void glitterRootTriangle(int r, GlitterVec3 v[3]);
void glitterChildTriangle(const GlitterVec3 parent[3], int j, GlitterVec3 child[3]);

// The surface: parameters of a checked GlitterRecord plus its integral table (the table must
// outlive the view).
struct GlitterSurface {
  GlitterDistribution distribution = GlitterDistribution::kBeckmann;
  double alpha = 0.1;
  uint64_t particles = 0;
  uint64_t seed = 0;
  int max_depth = 20;
  const GlitterIntegral* integrals = nullptr;
  size_t integral_count = 0;
};

// The tree shape: the query size the split rule is evaluated with (uv area of the spatial
// footprint, solid angle of the direction cone). Queries of one shape see one set of facets.
struct GlitterTreeShape {
  double area = 1e-4;
  double cone = 9.5699e-4;  // 2 pi (1 - cos 1 degree)
};

// One node of the hierarchy (see the top of this file).
struct GlitterNode {
  int uv_level = 0;
  uint32_t ix = 0, iy = 0;
  int dir_depth = 0;      // 0: the hemisphere
  uint64_t dir_code = 0;  // root index, then two bits per level
  GlitterVec3 tri[3];     // triangle vertices (depth >= 1)
  int64_t table = -1;     // entry of the integral table, -1 below the tabulated triangles
  uint64_t count = 0;
};

GlitterNode glitterRoot(const GlitterSurface& surface);
// Splits a node with count > 0 that is not a leaf: writes its four children (counts summing to
// node.count) and returns true for a spatial split, false for a directional one.
bool glitterSplit(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterNode& node,
                  GlitterNode children[4]);
bool glitterIsLeaf(const GlitterSurface& surface, const GlitterNode& node);
// Facet k (< node.count) of a leaf: uv position and unit normal.
void glitterLeafFacet(const GlitterSurface& surface, const GlitterNode& node, uint64_t k, double* u, double* v,
                      GlitterVec3* normal);
// Cell bounds [u0, u0 + size) x [v0, v0 + size) of a node.
void glitterCell(const GlitterNode& node, double* u0, double* v0, double* size);

// The uv region of a counting query: a rectangle of the periodic unit square, centre (u, v) and
// side lengths (wu, wv), cut at the seams into up to four half-open pieces of [0,1)^2. Sides >= 1
// cover the whole square along that axis.
struct GlitterUvRegion {
  double x0[4], y0[4], x1[4], y1[4];
  int pieces = 0;
  double area = 0.0;
  static GlitterUvRegion box(double u, double v, double wu, double wv);
};

// The direction region of a counting query.
struct GlitterDirRegion {
  enum Type { kCone, kRect, kTriangle, kAll } type = kAll;
  GlitterVec3 axis;         // kCone: unit axis
  double cos_gamma = 1.0;   // kCone: cosine of the half-angle (gamma <= kMaxGlitterGamma)
  double sx0 = 0, sy0 = 0;  // kRect: s-plane rectangle [sx0, sx1) x [sy0, sy1) of (h.x, h.y)
  double sx1 = 0, sy1 = 0;
  int tri_depth = 0;  // kTriangle: one triangle of the hierarchy (depth >= 1, code)
  uint64_t tri_code = 0;
  static GlitterDirRegion cone(const GlitterVec3& axis, double gamma);
  static GlitterDirRegion rect(double sx0, double sy0, double sx1, double sy1);
  static GlitterDirRegion triangle(int depth, uint64_t code);
  static GlitterDirRegion all() { return GlitterDirRegion(); }
  bool contains(const GlitterVec3& h) const;
};

struct GlitterCountOptions {
  // The binomial early stop: a node whose facets lie inside the query with probability o adds n o
  // when sqrt(n o (1 - o)) <= threshold * n o. o is the uv overlap fraction times the direction
  // fraction: 1 for a triangle inside the region, and for a triangle at most half as wide as the
  // region that straddles its edge (nodes of at least 64 facets), the share of D cos inside
  // estimated by four levels of sub-triangles (those on the edge by the share of their vertices and
  // centroid inside). Off: exact integer counts.
  bool early_stop = true;
  double early_stop_threshold = 0.1;
};

struct GlitterCountStats {
  uint64_t nodes = 0;   // nodes visited
  uint64_t facets = 0;  // leaf facets tested one by one
};

// Facets (expected count, with the early stop) inside uv region x direction region, seen through
// the tree shape. Thread-safe, no allocation.
double glitterCount(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterUvRegion& uv,
                    const GlitterDirRegion& dir, const GlitterCountOptions& options, GlitterCountStats* stats);

// A Gaussian spatial footprint: centre and standard deviations in uv units (the unit square
// repeats). Each facet weighs the mean of the normalised Gaussian over its cell of the resolution
// level (the coarsest uv level whose cells have a side of at most half the smaller std, or
// max_depth), so a facet's weight depends on its cell only, whatever the query; cells beyond 4 std
// (nearest periodic image) weigh 0.
struct GlitterGaussian {
  double u = 0.5, v = 0.5;
  double sigma_u = 0.01, sigma_v = 0.01;
};

// Sum over the facets inside `dir` of the footprint weight (per unit uv area: the weights of
// all facets of the unit square sum to about N). Thread-safe, no allocation.
double glitterWeightedCount(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                            const GlitterDirRegion& dir, GlitterCountStats* stats);

// Adds the footprint-weighted facets into res x res bins over s in [-1, 1]^2 (row 0 at s_y = +1;
// SPEC.md section 9), each facet into the bin holding (h.x, h.y): bins[j * res + i] += weight.
// Bins whose centre lies outside the unit disk receive nothing. Thread-safe, no allocation.
void glitterBinnedWeights(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                          int res, double* bins, GlitterCountStats* stats);
void glitterBinnedWeights(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                          int res, float* bins, GlitterCountStats* stats);

// Picks one facet with probability proportional to its footprint weight, from u in [0, 1), and
// returns its normal and the total weight (exactly glitterWeightedCount over all directions);
// false when the footprint holds no weight. Costs two weighted counts (the total, then the same
// traversal up to the chosen cell of the resolution level) and a descent by counts below it.
// Thread-safe, no allocation.
bool glitterSampleFacet(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                        double u, GlitterVec3* normal, double* total_weight, GlitterCountStats* stats);

// The unit direction at polar angle acos(cos_theta) and azimuth phi around axis (any orthonormal
// frame; the same for every call).
GlitterVec3 glitterConeDirection(const GlitterVec3& axis, double cos_theta, double phi);

// Splitmix64 finaliser and the uniform in [0, 1) of stream `h` at position k (the draws of the model).
uint64_t glitterMix(uint64_t x);
double glitterUniform(uint64_t h, uint64_t k);

}  // namespace glintbake::format
