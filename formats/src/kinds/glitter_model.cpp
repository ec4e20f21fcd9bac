// SPDX-License-Identifier: Apache-2.0
// The discrete stochastic microfacet surface of glitter assets (see kinds/glitter_model.h).
#include <glintbake/format/kinds/glitter_model.h>
#include <glintbake/format/numbers.h>

#include <algorithm>
#include <cmath>

namespace glintbake::format {
namespace {

constexpr int kExactDraws = 8;         // categorical draws per facet below this count
constexpr double kFootprintReach = 4;  // Gaussian footprints are cut at this many std
enum Overlap { kDisjoint = 0, kInside = 1, kPartial = 2 };
enum Tag : uint64_t { kTagSpace = 1, kTagDirection = 2, kTagLeaf = 3 };

double dot(const GlitterVec3& a, const GlitterVec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
GlitterVec3 add(const GlitterVec3& a, const GlitterVec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
GlitterVec3 scale(const GlitterVec3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
GlitterVec3 normalise(const GlitterVec3& a) { return scale(a, 1.0 / std::sqrt(dot(a, a))); }
GlitterVec3 cross(const GlitterVec3& a, const GlitterVec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
GlitterVec3 centroid(const GlitterVec3 v[3]) { return normalise(add(add(v[0], v[1]), v[2])); }

uint64_t nodeHash(const GlitterSurface& s, const GlitterNode& n, Tag tag) {
  uint64_t h = glitterMix(s.seed ^ 0x676c6974746572ull);
  h = glitterMix(h ^ (uint64_t(n.uv_level) | (uint64_t(n.dir_depth) << 8) | (uint64_t(tag) << 16)));
  h = glitterMix(h ^ (uint64_t(n.ix) | (uint64_t(n.iy) << 32)));
  return glitterMix(h ^ n.dir_code);
}

// Multinomial split of n over four categories of probabilities p (summing to 1).
void multinomial4(uint64_t n, const double p[4], uint64_t h, uint64_t out[4]) {
  for (int c = 0; c < 4; ++c) out[c] = 0;
  int last = 0;  // the last category with p > 0 takes rounding leftovers
  for (int c = 0; c < 4; ++c)
    if (p[c] > 0.0) last = c;
  if (n < uint64_t(kExactDraws)) {
    for (uint64_t k = 0; k < n; ++k) {
      const double u = glitterUniform(h, k);
      int c = 0;
      double acc = p[0];
      while (c < last && !(u < acc)) acc += p[++c];
      ++out[c];
    }
    return;
  }
  // Gaussian approximation: x = n p + y - p sum(y), y_i = sqrt(n p_i) z_i, has mean n p,
  // covariance n (diag p - p p^T) and sums to n exactly.
  double z[4];
  for (int i = 0; i < 2; ++i) {
    const double r = std::sqrt(-2.0 * std::log(1.0 - glitterUniform(h, uint64_t(2 * i))));
    const double t = 2.0 * kPi * glitterUniform(h, uint64_t(2 * i + 1));
    z[2 * i] = r * std::cos(t);
    z[2 * i + 1] = r * std::sin(t);
  }
  const double nd = double(n);
  double y[4], sum_y = 0.0;
  for (int c = 0; c < 4; ++c) {
    y[c] = std::sqrt(nd * p[c]) * z[c];
    sum_y += y[c];
  }
  int64_t total = 0;
  for (int c = 0; c < 4; ++c) {
    if (!(p[c] > 0.0)) continue;
    const double x = std::nearbyint(nd * p[c] + y[c] - p[c] * sum_y);
    out[c] = x <= 0.0 ? 0 : (x >= nd ? n : uint64_t(x));
    total += int64_t(out[c]);
  }
  // Repair: the excess comes off the largest counts, a deficit goes to the likeliest category.
  int64_t diff = int64_t(n) - total;
  if (diff > 0) {
    int best = 0;
    for (int c = 1; c < 4; ++c)
      if (p[c] > p[best]) best = c;
    out[best] += uint64_t(diff);
  }
  while (diff < 0) {
    int big = 0;
    for (int c = 1; c < 4; ++c)
      if (out[c] > out[big]) big = c;
    const uint64_t take = std::min<uint64_t>(out[big], uint64_t(-diff));
    out[big] -= take;
    diff += int64_t(take);
  }
}

double triangleArea(const GlitterNode& n) {
  return n.dir_depth == 0 ? 2.0 * kPi : sphericalTriangleArea(n.tri[0], n.tri[1], n.tri[2]);
}

bool splitsSpace(const GlitterSurface& s, const GlitterTreeShape& shape, const GlitterNode& n) {
  if (n.uv_level >= s.max_depth) return false;
  if (n.dir_depth >= s.max_depth) return true;
  const double uv_area = std::ldexp(1.0, -2 * n.uv_level);
  return 0.25 * shape.cone * uv_area > shape.area * triangleArea(n);
}

// Extremes of (h.x, h.y) over a spherical triangle: at the vertices or inside an edge arc (the
// only interior critical points of a linear function on the sphere, +-x and +-y, are vertices or
// on edges of every triangle of the hierarchy).
void triangleBounds(const GlitterVec3 v[3], double lo[2], double hi[2]) {
  lo[0] = lo[1] = 2.0;
  hi[0] = hi[1] = -2.0;
  for (int e = 0; e < 3; ++e) {
    const GlitterVec3& a = v[e];
    const GlitterVec3& b = v[(e + 1) % 3];
    const double ab = std::clamp(dot(a, b), -1.0, 1.0);
    const double theta = std::acos(ab);
    GlitterVec3 w = add(b, scale(a, -ab));
    const double wl = std::sqrt(dot(w, w));
    for (int axis = 0; axis < 2; ++axis) {
      const double la = axis == 0 ? a.x : a.y;
      lo[axis] = std::min(lo[axis], la);
      hi[axis] = std::max(hi[axis], la);
      if (wl < 1e-300) continue;
      const double lw = (axis == 0 ? w.x : w.y) / wl;
      double t = std::atan2(lw, la);
      for (int k = 0; k < 2; ++k, t += kPi) {
        double tt = std::fmod(t + 4.0 * kPi, 2.0 * kPi);
        if (tt <= theta) {
          const double val = la * std::cos(tt) + lw * std::sin(tt);
          lo[axis] = std::min(lo[axis], val);
          hi[axis] = std::max(hi[axis], val);
        }
      }
    }
  }
}

Overlap classifyDir(const GlitterDirRegion& d, const GlitterNode& n) {
  if (d.type == GlitterDirRegion::kAll) return kInside;
  if (n.dir_depth == 0) {
    if (d.type == GlitterDirRegion::kRect && d.sx0 <= -1.0 && d.sy0 <= -1.0 && d.sx1 > 1.0 && d.sy1 > 1.0)
      return kInside;
    return kPartial;
  }
  switch (d.type) {
    case GlitterDirRegion::kCone: {
      if (dot(n.tri[0], d.axis) >= d.cos_gamma && dot(n.tri[1], d.axis) >= d.cos_gamma &&
          dot(n.tri[2], d.axis) >= d.cos_gamma)
        return kInside;  // a cap of at most 90 degrees is convex
      // The triangle lies in the cap around its centroid reaching its farthest vertex.
      const GlitterVec3 c = centroid(n.tri);
      double radius = 0.0;
      for (int i = 0; i < 3; ++i) radius = std::max(radius, std::acos(std::clamp(dot(c, n.tri[i]), -1.0, 1.0)));
      const double gamma = std::acos(std::clamp(d.cos_gamma, -1.0, 1.0));
      const double apart = std::acos(std::clamp(dot(c, d.axis), -1.0, 1.0));
      return apart > gamma + radius + 1e-12 ? kDisjoint : kPartial;
    }
    case GlitterDirRegion::kRect: {
      double lo[2], hi[2];
      triangleBounds(n.tri, lo, hi);
      if (hi[0] < d.sx0 || lo[0] >= d.sx1 || hi[1] < d.sy0 || lo[1] >= d.sy1) return kDisjoint;
      if (lo[0] >= d.sx0 && hi[0] < d.sx1 && lo[1] >= d.sy0 && hi[1] < d.sy1) return kInside;
      return kPartial;
    }
    case GlitterDirRegion::kTriangle: {
      if (n.dir_depth >= d.tri_depth)
        return (n.dir_code >> (2 * (n.dir_depth - d.tri_depth))) == d.tri_code ? kInside : kDisjoint;
      return (d.tri_code >> (2 * (d.tri_depth - n.dir_depth))) == n.dir_code ? kPartial : kDisjoint;
    }
    default:
      return kInside;
  }
}

// Overlap of a node's cell with the uv region, and the covered fraction of the cell.
Overlap classifyUv(const GlitterUvRegion& r, const GlitterNode& n, double* fraction) {
  double u0, v0, size;
  glitterCell(n, &u0, &v0, &size);
  double covered = 0.0;
  for (int p = 0; p < r.pieces; ++p) {
    const double w = std::min(u0 + size, r.x1[p]) - std::max(u0, r.x0[p]);
    const double h = std::min(v0 + size, r.y1[p]) - std::max(v0, r.y0[p]);
    if (w <= 0.0 || h <= 0.0) continue;
    if (r.x0[p] <= u0 && u0 + size <= r.x1[p] && r.y0[p] <= v0 && v0 + size <= r.y1[p]) {
      *fraction = 1.0;
      return kInside;
    }
    covered += w * h;
  }
  *fraction = covered / (size * size);
  return covered > 0.0 ? kPartial : kDisjoint;
}

bool uvContains(const GlitterUvRegion& r, double u, double v) {
  for (int p = 0; p < r.pieces; ++p)
    if (u >= r.x0[p] && u < r.x1[p] && v >= r.y0[p] && v < r.y1[p]) return true;
  return false;
}

// Fraction of the mass of D cos over a triangle that lies inside a cone or rectangle, by adaptive
// subdivision: sub-triangles inside count fully, partial ones at the last level by the share of
// their vertices and centroid inside, each
// weighted by its centroid rule. Used by the early stop of nodes whose triangle straddles the
// region's edge (where the paper's rule would otherwise refine every facet near the edge).
double regionFraction(const GlitterSurface& s, const GlitterDirRegion& d, const GlitterVec3 v[3], int levels,
                      double* mass) {
  GlitterNode probe;
  probe.dir_depth = 1;
  probe.tri[0] = v[0], probe.tri[1] = v[1], probe.tri[2] = v[2];
  const double m = glitterNdfCos(s.distribution, s.alpha, centroid(v)) * sphericalTriangleArea(v[0], v[1], v[2]);
  *mass = m;
  const Overlap o = classifyDir(d, probe);
  if (o == kInside) return m;
  if (o == kDisjoint) return 0.0;
  if (levels == 0) {
    const int in = int(d.contains(v[0])) + int(d.contains(v[1])) + int(d.contains(v[2])) + int(d.contains(centroid(v)));
    return 0.25 * in * m;
  }
  double inside = 0.0, total = 0.0;
  for (int j = 0; j < 4; ++j) {
    GlitterVec3 c[3];
    glitterChildTriangle(v, j, c);
    double cm = 0.0;
    inside += regionFraction(s, d, c, levels - 1, &cm);
    total += cm;
  }
  *mass = total;
  return inside;
}

constexpr int kFractionLevels = 4;     // sub-triangle levels of regionFraction
constexpr uint64_t kFractionMin = 64;  // nodes with fewer facets are not worth the estimate

struct CountContext {
  const GlitterSurface& surface;
  const GlitterTreeShape& shape;
  const GlitterUvRegion& uv;
  const GlitterDirRegion& dir;
  const GlitterCountOptions& options;
  GlitterCountStats& stats;
};

double countNode(const CountContext& c, const GlitterNode& node) {
  ++c.stats.nodes;
  if (node.count == 0) return 0.0;
  double fraction = 0.0;
  const Overlap uv = classifyUv(c.uv, node, &fraction);
  if (uv == kDisjoint) return 0.0;
  const Overlap dir = classifyDir(c.dir, node);
  if (dir == kDisjoint) return 0.0;
  const double n = double(node.count);
  if (uv == kInside && dir == kInside) return n;
  if (c.options.early_stop && (dir == kInside || node.count >= kFractionMin)) {
    // The facets inside are binomial with the overlap fraction o: stop when their relative std is
    // small. The uv fraction is exact; the direction fraction is exact for a triangle inside the
    // region and estimated by subdivision for a small triangle on its edge.
    double o = fraction;
    bool known = dir == kInside;
    if (!known && node.dir_depth >= 1 &&
        (c.dir.type == GlitterDirRegion::kCone || c.dir.type == GlitterDirRegion::kRect)) {
      double lo[2], hi[2];
      triangleBounds(node.tri, lo, hi);
      const double extent = std::max(hi[0] - lo[0], hi[1] - lo[1]);
      const double region = c.dir.type == GlitterDirRegion::kCone
                                ? std::sqrt(std::max(0.0, 1.0 - c.dir.cos_gamma * c.dir.cos_gamma))
                                : std::min(c.dir.sx1 - c.dir.sx0, c.dir.sy1 - c.dir.sy0);
      if (extent <= 0.5 * region) {
        double mass = 0.0;
        const double in = regionFraction(c.surface, c.dir, node.tri, kFractionLevels, &mass);
        o *= mass > 0.0 ? in / mass : 0.0;
        known = true;
      }
    }
    const double mean = n * o;
    if (known && mean > 0.0 && std::sqrt(mean * (1.0 - o)) <= c.options.early_stop_threshold * mean) return mean;
  }
  if (glitterIsLeaf(c.surface, node)) {
    double hits = 0.0;
    for (uint64_t k = 0; k < node.count; ++k) {
      double u, v;
      GlitterVec3 h;
      glitterLeafFacet(c.surface, node, k, &u, &v, &h);
      ++c.stats.facets;
      if (uvContains(c.uv, u, v) && c.dir.contains(h)) hits += 1.0;
    }
    return hits;
  }
  GlitterNode children[4];
  glitterSplit(c.surface, c.shape, node, children);
  double sum = 0.0;
  for (const GlitterNode& child : children) sum += countNode(c, child);
  return sum;
}

// Gaussian footprints: distance of a cell to the footprint centre on the periodic unit square, and
// the mean of the normalised Gaussian over the cell (summed over the periodic images it reaches).
double axisGap(double lo, double size, double centre) {
  const double mid = lo + 0.5 * size;
  double d = std::fabs(centre - mid);
  d -= std::floor(d);
  d = std::min(d, 1.0 - d);
  return std::max(0.0, d - 0.5 * size);
}
double axisMean(double lo, double size, double centre, double sigma) {
  const int reach = int(std::ceil(kFootprintReach * sigma)) + 1;
  const double shift = std::floor(centre);
  const double inv = 1.0 / (sigma * std::sqrt(2.0));
  double sum = 0.0;
  for (int k = -reach; k <= reach; ++k) {
    const double a = (lo + k + shift - centre) * inv, b = (lo + size + k + shift - centre) * inv;
    if (b < -kFootprintReach || a > kFootprintReach) continue;
    sum += 0.5 * (std::erf(b) - std::erf(a));
  }
  return sum / size;
}

struct WeightContext {
  const GlitterSurface& surface;
  const GlitterTreeShape& shape;
  const GlitterGaussian& fp;
  const GlitterDirRegion* dir;  // weighted count
  int res;                      // binned weights (dir == null), into bins or fbins
  double* bins;
  float* fbins;
  GlitterCountStats& stats;
  int level;  // the resolution level (resolutionLevel)
};

// The uv level whose cells weigh their facets: the coarsest with a side of at most half the
// footprint's smaller std (or max_depth). Every facet's weight is the mean of the Gaussian over
// its cell of this level, whichever query asks.
int resolutionLevel(const GlitterSurface& s, const GlitterGaussian& fp) {
  const double sigma = std::min(fp.sigma_u, fp.sigma_v);
  int level = 0;
  while (level < s.max_depth && std::ldexp(1.0, -level) > 0.5 * sigma) ++level;
  return level;
}

// Mean Gaussian weight of the resolution cell holding a node at or below the resolution level.
double cellWeight(const GlitterGaussian& fp, const GlitterNode& n, int level) {
  const int up = n.uv_level - level;
  const double size = std::ldexp(1.0, -level);
  const double u0 = double(n.ix >> up) * size, v0 = double(n.iy >> up) * size;
  return axisMean(u0, size, fp.u, fp.sigma_u) * axisMean(v0, size, fp.v, fp.sigma_v);
}

bool beyondFootprint(const GlitterGaussian& fp, const GlitterNode& n) {
  double u0, v0, size;
  glitterCell(n, &u0, &v0, &size);
  return axisGap(u0, size, fp.u) > kFootprintReach * fp.sigma_u ||
         axisGap(v0, size, fp.v) > kFootprintReach * fp.sigma_v;
}

// Bin of an s-plane point (-1 outside the unit-disk bins).
int binOf(int res, double x, double y) {
  const int i = std::clamp(int(std::floor((x + 1.0) * 0.5 * res)), 0, res - 1);
  const int j = std::clamp(int(std::floor((1.0 - y) * 0.5 * res)), 0, res - 1);
  const double cx = -1.0 + (i + 0.5) * 2.0 / res, cy = 1.0 - (j + 0.5) * 2.0 / res;
  return cx * cx + cy * cy > 1.0 ? -1 : j * res + i;
}

// Bin that holds the whole triangle, or -2 when it straddles bins.
int triangleBin(int res, const GlitterNode& n) {
  if (n.dir_depth == 0) return -2;
  double lo[2], hi[2];
  triangleBounds(n.tri, lo, hi);
  const int i0 = std::clamp(int(std::floor((lo[0] + 1.0) * 0.5 * res)), 0, res - 1);
  const int i1 = std::clamp(int(std::floor((hi[0] + 1.0) * 0.5 * res)), 0, res - 1);
  const int j0 = std::clamp(int(std::floor((1.0 - hi[1]) * 0.5 * res)), 0, res - 1);
  const int j1 = std::clamp(int(std::floor((1.0 - lo[1]) * 0.5 * res)), 0, res - 1);
  if (i0 != i1 || j0 != j1) return -2;
  return binOf(res, -1.0 + (i0 + 0.5) * 2.0 / res, 1.0 - (j0 + 0.5) * 2.0 / res);
}

// `known` is the resolution cell's weight once a node is at or below the resolution level (-1 above).
double weightNode(const WeightContext& c, const GlitterNode& node, double known = -1.0) {
  ++c.stats.nodes;
  if (node.count == 0 || (known < 0.0 && beyondFootprint(c.fp, node))) return 0.0;
  const bool resolved = node.uv_level >= c.level;
  if (resolved && known < 0.0) known = cellWeight(c.fp, node, c.level);
  const bool leaf = glitterIsLeaf(c.surface, node);
  if (c.dir) {
    const Overlap dir = classifyDir(*c.dir, node);
    if (dir == kDisjoint) return 0.0;
    if (resolved && dir == kInside) return double(node.count) * known;
    if (leaf) return c.dir->contains(centroid(node.tri)) ? double(node.count) * known : 0.0;
  } else {
    const int bin = leaf ? binOf(c.res, centroid(node.tri).x, centroid(node.tri).y) : triangleBin(c.res, node);
    if (resolved && bin != -2) {
      if (bin >= 0) {
        const double w = double(node.count) * known;
        if (c.bins) c.bins[bin] += w;
        if (c.fbins) c.fbins[bin] += float(w);
      }
      return 0.0;
    }
  }
  GlitterNode children[4];
  glitterSplit(c.surface, c.shape, node, children);
  double sum = 0.0;
  for (const GlitterNode& child : children) sum += weightNode(c, child, known);
  return sum;
}

// The resolved node (a cell of the resolution level, or a leaf) holding the target-th unit of
// footprint weight, visiting the nodes in weightNode's order (dir = all): *acc sums the weights of
// the resolved nodes before it. *last keeps the last node of positive weight, for a target that
// rounding leaves just beyond the sum. True once found; *rest is the target's position inside it.
bool pickResolved(const WeightContext& c, const GlitterNode& node, double known, double target, double* acc,
                  GlitterNode* picked, double* rest, GlitterNode* last, double* last_weight) {
  ++c.stats.nodes;
  if (node.count == 0 || (known < 0.0 && beyondFootprint(c.fp, node))) return false;
  if (node.uv_level >= c.level) {
    if (known < 0.0) known = cellWeight(c.fp, node, c.level);
    const double w = double(node.count) * known;
    if (!(w > 0.0)) return false;
    *last = node;
    *last_weight = w;
    if (target < *acc + w) {
      *picked = node;
      *rest = (target - *acc) / w;
      return true;
    }
    *acc += w;
    return false;
  }
  GlitterNode children[4];
  glitterSplit(c.surface, c.shape, node, children);
  for (const GlitterNode& child : children)
    if (pickResolved(c, child, known, target, acc, picked, rest, last, last_weight)) return true;
  return false;
}

}  // namespace

uint64_t glitterMix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

double glitterUniform(uint64_t h, uint64_t k) {
  return double(glitterMix(h + (k + 1) * 0x9E3779B97F4A7C15ull) >> 11) * 0x1p-53;
}

double glitterNdfCos(GlitterDistribution d, double alpha, const GlitterVec3& h) {
  if (!(h.z > 0.0)) return 0.0;
  const double c2 = h.z * h.z;
  const double a2 = alpha * alpha;
  if (d == GlitterDistribution::kGgx) {
    const double t = c2 * (a2 - 1.0) + 1.0;
    return a2 / (kPi * t * t) * h.z;
  }
  const double tan2 = std::max(0.0, 1.0 - c2) / c2;
  return std::exp(-tan2 / a2) / (kPi * a2 * c2 * c2) * h.z;
}

double sphericalTriangleArea(const GlitterVec3& a, const GlitterVec3& b, const GlitterVec3& c) {
  const double num = std::fabs(dot(a, cross(b, c)));
  const double den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
  return 2.0 * std::atan2(num, den);
}

void glitterRootTriangle(int r, GlitterVec3 v[3]) {
  static const GlitterVec3 kRim[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  v[0] = {0, 0, 1};
  v[1] = kRim[r & 3];
  v[2] = kRim[(r + 1) & 3];
}

void glitterChildTriangle(const GlitterVec3 p[3], int j, GlitterVec3 child[3]) {
  const GlitterVec3 m01 = normalise(add(p[0], p[1]));
  const GlitterVec3 m12 = normalise(add(p[1], p[2]));
  const GlitterVec3 m20 = normalise(add(p[2], p[0]));
  switch (j) {
    case 0:
      child[0] = p[0], child[1] = m01, child[2] = m20;
      break;
    case 1:
      child[0] = m01, child[1] = p[1], child[2] = m12;
      break;
    case 2:
      child[0] = m20, child[1] = m12, child[2] = p[2];
      break;
    default:
      child[0] = m01, child[1] = m12, child[2] = m20;
      break;
  }
}

GlitterNode glitterRoot(const GlitterSurface& surface) {
  GlitterNode n;
  n.count = surface.particles;
  return n;
}

bool glitterIsLeaf(const GlitterSurface& s, const GlitterNode& n) {
  return n.uv_level >= s.max_depth && n.dir_depth >= s.max_depth;
}

bool glitterSplit(const GlitterSurface& s, const GlitterTreeShape& shape, const GlitterNode& node,
                  GlitterNode children[4]) {
  double p[4];
  uint64_t counts[4];
  if (splitsSpace(s, shape, node)) {
    for (int j = 0; j < 4; ++j) {
      children[j] = node;
      children[j].uv_level = node.uv_level + 1;
      children[j].ix = 2 * node.ix + uint32_t(j & 1);
      children[j].iy = 2 * node.iy + uint32_t(j >> 1);
      p[j] = 0.25;
    }
    multinomial4(node.count, p, nodeHash(s, node, kTagSpace), counts);
    for (int j = 0; j < 4; ++j) children[j].count = counts[j];
    return true;
  }
  int64_t first = -1;  // tabulated children, if any
  if (node.dir_depth == 0) {
    if (s.integral_count >= 4) first = 0;
  } else if (node.table >= 0 && size_t(node.table) < s.integral_count) {
    const uint32_t fc = s.integrals[node.table].first_child;
    if (fc != 0 && size_t(fc) + 3 < s.integral_count) first = int64_t(fc);
  }
  double total = 0.0;
  for (int j = 0; j < 4; ++j) {
    GlitterNode& c = children[j];
    c = node;
    c.dir_depth = node.dir_depth + 1;
    c.dir_code = node.dir_depth == 0 ? uint64_t(j) : node.dir_code * 4 + uint64_t(j);
    if (node.dir_depth == 0) {
      glitterRootTriangle(j, c.tri);
    } else {
      glitterChildTriangle(node.tri, j, c.tri);
    }
    c.table = first >= 0 ? first + j : -1;
    p[j] = first >= 0 ? s.integrals[first + j].integral
                      : glitterNdfCos(s.distribution, s.alpha, centroid(c.tri)) *
                            sphericalTriangleArea(c.tri[0], c.tri[1], c.tri[2]);
    total += p[j];
  }
  if (total > 0.0) {
    for (int j = 0; j < 4; ++j) p[j] /= total;
  } else {
    // Far in the tail every rule underflows: split by solid angle.
    double area_total = 0.0;
    for (int j = 0; j < 4; ++j) {
      p[j] = sphericalTriangleArea(children[j].tri[0], children[j].tri[1], children[j].tri[2]);
      area_total += p[j];
    }
    for (int j = 0; j < 4; ++j) p[j] /= area_total;
  }
  multinomial4(node.count, p, nodeHash(s, node, kTagDirection), counts);
  for (int j = 0; j < 4; ++j) children[j].count = counts[j];
  return false;
}

void glitterCell(const GlitterNode& n, double* u0, double* v0, double* size) {
  *size = std::ldexp(1.0, -n.uv_level);
  *u0 = n.ix * *size;
  *v0 = n.iy * *size;
}

void glitterLeafFacet(const GlitterSurface& s, const GlitterNode& n, uint64_t k, double* u, double* v,
                      GlitterVec3* normal) {
  const uint64_t h = nodeHash(s, n, kTagLeaf);
  double u0, v0, size;
  glitterCell(n, &u0, &v0, &size);
  *u = u0 + glitterUniform(h, 2 * k) * size;
  *v = v0 + glitterUniform(h, 2 * k + 1) * size;
  *normal = centroid(n.tri);
}

GlitterUvRegion GlitterUvRegion::box(double u, double v, double wu, double wv) {
  GlitterUvRegion r;
  double ax0[2], ax1[2], ay0[2], ay1[2];
  int nx = 0, ny = 0;
  const auto axis = [](double c, double w, double* lo, double* hi, int* count) {
    if (w >= 1.0) {
      lo[0] = 0.0, hi[0] = 1.0, *count = 1;
      return 1.0;
    }
    double a = c - 0.5 * w;
    a -= std::floor(a);
    const double b = a + w;
    lo[0] = a, hi[0] = std::min(b, 1.0), *count = 1;
    if (b > 1.0) lo[1] = 0.0, hi[1] = b - 1.0, *count = 2;
    return w;
  };
  const double lu = axis(u, wu, ax0, ax1, &nx);
  const double lv = axis(v, wv, ay0, ay1, &ny);
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      r.x0[r.pieces] = ax0[i], r.x1[r.pieces] = ax1[i];
      r.y0[r.pieces] = ay0[j], r.y1[r.pieces] = ay1[j];
      ++r.pieces;
    }
  }
  r.area = lu * lv;
  return r;
}

GlitterDirRegion GlitterDirRegion::cone(const GlitterVec3& axis, double gamma) {
  GlitterDirRegion d;
  d.type = kCone;
  d.axis = normalise(axis);
  d.cos_gamma = std::cos(gamma);
  return d;
}

GlitterDirRegion GlitterDirRegion::rect(double x0, double y0, double x1, double y1) {
  GlitterDirRegion d;
  d.type = kRect;
  d.sx0 = x0, d.sy0 = y0, d.sx1 = x1, d.sy1 = y1;
  return d;
}

GlitterDirRegion GlitterDirRegion::triangle(int depth, uint64_t code) {
  GlitterDirRegion d;
  d.type = kTriangle;
  d.tri_depth = depth;
  d.tri_code = code;
  return d;
}

bool GlitterDirRegion::contains(const GlitterVec3& h) const {
  switch (type) {
    case kCone:
      return dot(h, axis) >= cos_gamma;
    case kRect:
      return h.x >= sx0 && h.x < sx1 && h.y >= sy0 && h.y < sy1;
    default:
      return true;  // triangles are decided per leaf node, never per facet
  }
}

double glitterCount(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterUvRegion& uv,
                    const GlitterDirRegion& dir, const GlitterCountOptions& options, GlitterCountStats* stats) {
  GlitterCountStats local;
  const CountContext c{surface, shape, uv, dir, options, stats ? *stats : local};
  return countNode(c, glitterRoot(surface));
}

double glitterWeightedCount(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                            const GlitterDirRegion& dir, GlitterCountStats* stats) {
  GlitterCountStats local;
  const WeightContext c{
      surface, shape, fp, &dir, 0, nullptr, nullptr, stats ? *stats : local, resolutionLevel(surface, fp)};
  return weightNode(c, glitterRoot(surface));
}

namespace {
void binnedWeights(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp, int res,
                   double* bins, float* fbins, GlitterCountStats* stats) {
  GlitterCountStats local;
  const WeightContext c{
      surface, shape, fp, nullptr, res, bins, fbins, stats ? *stats : local, resolutionLevel(surface, fp)};
  weightNode(c, glitterRoot(surface));
}
}  // namespace

void glitterBinnedWeights(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                          int res, double* bins, GlitterCountStats* stats) {
  binnedWeights(surface, shape, fp, res, bins, nullptr, stats);
}

void glitterBinnedWeights(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                          int res, float* bins, GlitterCountStats* stats) {
  binnedWeights(surface, shape, fp, res, nullptr, bins, stats);
}

GlitterVec3 glitterConeDirection(const GlitterVec3& axis, double cos_theta, double phi) {
  const GlitterVec3 z = normalise(axis);
  GlitterVec3 t = std::fabs(z.x) < 0.9 ? GlitterVec3{1, 0, 0} : GlitterVec3{0, 1, 0};
  t = normalise(add(t, scale(z, -dot(t, z))));
  const GlitterVec3 b = cross(z, t);
  const double st = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  return add(add(scale(t, st * std::cos(phi)), scale(b, st * std::sin(phi))), scale(z, cos_theta));
}

bool glitterSampleFacet(const GlitterSurface& surface, const GlitterTreeShape& shape, const GlitterGaussian& fp,
                        double u, GlitterVec3* normal, double* total_weight, GlitterCountStats* stats) {
  GlitterCountStats local;
  const GlitterDirRegion all = GlitterDirRegion::all();
  const WeightContext c{
      surface, shape, fp, &all, 0, nullptr, nullptr, stats ? *stats : local, resolutionLevel(surface, fp)};
  GlitterNode node = glitterRoot(surface);
  const double root_weight = weightNode(c, node);
  if (total_weight) *total_weight = root_weight;
  if (!(root_weight > 0.0)) return false;
  // A second pass in the same order finds the resolved node (every facet below it weighs the same)
  // holding u x the total weight: two weighted counts in all, whatever the depth.
  {
    double acc = 0.0, rest = 0.0, last_weight = 0.0;
    GlitterNode picked, last;
    if (pickResolved(c, node, -1.0, u * root_weight, &acc, &picked, &rest, &last, &last_weight)) {
      node = picked;
    } else if (last_weight > 0.0) {
      node = last;  // u x total beyond the running sum by rounding: the last node of weight
      rest = 1.0;
    } else {
      return false;
    }
    u = std::clamp(rest, 0.0, std::nextafter(1.0, 0.0));
  }
  // Below it, children are chosen by their counts.
  while (!glitterIsLeaf(surface, node)) {
    GlitterNode children[4];
    glitterSplit(surface, shape, node, children);
    double w[4], total = 0.0;
    for (int j = 0; j < 4; ++j) {
      w[j] = double(children[j].count);
      total += w[j];
    }
    if (!(total > 0.0)) return false;
    double target = u * total, acc = 0.0;
    int pick = -1;
    for (int j = 0; j < 4; ++j) {
      if (!(w[j] > 0.0)) continue;
      pick = j;
      if (target < acc + w[j]) break;
      acc += w[j];
    }
    u = std::clamp((target - acc) / w[pick], 0.0, std::nextafter(1.0, 0.0));
    node = children[pick];
  }
  *normal = centroid(node.tri);
  return true;
}

}  // namespace glintbake::format
