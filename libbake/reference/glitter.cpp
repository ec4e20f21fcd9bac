// SPDX-License-Identifier: Apache-2.0
#include <glintbake/format/numbers.h>
#include <glintbake/reference/glitter.h>

#include <cmath>

namespace glintbake::reference {
namespace {

void descend(const format::GlitterSurface& s, const format::GlitterTreeShape& shape, const format::GlitterNode& node,
             std::vector<GlitterFacet>* out) {
  if (node.count == 0) return;
  if (format::glitterIsLeaf(s, node)) {
    for (uint64_t k = 0; k < node.count; ++k) {
      GlitterFacet f;
      format::glitterLeafFacet(s, node, k, &f.u, &f.v, &f.normal);
      f.leaf_code = node.dir_code;
      f.leaf_depth = node.dir_depth;
      out->push_back(f);
    }
    return;
  }
  format::GlitterNode children[4];
  format::glitterSplit(s, shape, node, children);
  for (const format::GlitterNode& c : children) descend(s, shape, c, out);
}

bool inUv(const format::GlitterUvRegion& r, double u, double v) {
  for (int p = 0; p < r.pieces; ++p)
    if (u >= r.x0[p] && u < r.x1[p] && v >= r.y0[p] && v < r.y1[p]) return true;
  return false;
}

}  // namespace

std::vector<GlitterFacet> enumerateGlitterFacets(const format::GlitterSurface& surface,
                                                 const format::GlitterTreeShape& shape) {
  std::vector<GlitterFacet> facets;
  facets.reserve(size_t(surface.particles));
  descend(surface, shape, format::glitterRoot(surface), &facets);
  return facets;
}

uint64_t countGlitterFacets(const std::vector<GlitterFacet>& facets, const format::GlitterUvRegion& uv,
                            const format::GlitterDirRegion& dir) {
  uint64_t n = 0;
  for (const GlitterFacet& f : facets) {
    bool in_dir = dir.contains(f.normal);
    if (dir.type == format::GlitterDirRegion::kTriangle) {
      const int below = 2 * (f.leaf_depth - dir.tri_depth);
      in_dir = below >= 0 && (f.leaf_code >> below) == dir.tri_code;
    }
    if (in_dir && inUv(uv, f.u, f.v)) ++n;
  }
  return n;
}

double smoothGlitterCone(format::GlitterDistribution distribution, double alpha, const format::GlitterVec3& axis,
                         double gamma) {
  constexpr int kTheta = 64, kPhi = 128;
  double sum = 0.0;
  for (int i = 0; i < kTheta; ++i) {
    const double th = (i + 0.5) * gamma / kTheta;
    const double w = std::sin(th) * (gamma / kTheta) * (2.0 * kPi / kPhi);
    for (int j = 0; j < kPhi; ++j) {
      const double ph = (j + 0.5) * 2.0 * kPi / kPhi;
      const format::GlitterVec3 h = format::glitterConeDirection(axis, std::cos(th), ph);
      sum += format::glitterNdfCos(distribution, alpha, h) * w;
    }
  }
  return sum / (2.0 * kPi * (1.0 - std::cos(gamma)));
}

}  // namespace glintbake::reference
