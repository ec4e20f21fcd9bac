// SPDX-License-Identifier: Apache-2.0
// The exact small-footprint P-NDF from a normal map's flakes (see flake_ndf.h).
#include <glintbake/runtime/flake_ndf.h>

#include "../heap_array.h"
#include "../pyramid_blend.h"
#include "flake_model.h"
#include "float4.h"
#include "gaussian_rect.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::runtime {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
constexpr int kTile = 8;             // flakes per side of a tile of the hierarchy
constexpr int kLeafFlakes = 8;       // flakes per leaf of a tile's k-d tree (one block)
constexpr double kWindowSigmas = 6;  // spatial truncation radius, in sqrt(v), as the reference's
// A flake is left out when its spatial exponent |u_Q - u_k|^2 / 2v plus its lobe's exponent at s
// exceeds this: its contribution is below e^-18 of its own peak. The spatial part alone is the
// reference evaluator's truncation (a disk of 6 sqrt(v)).
constexpr double kMaxExponent = kWindowSigmas * kWindowSigmas / 2;
constexpr float kPaddingPosition = 1e15f;  // position of the unused lanes of a block: weight 0
constexpr int kMaxSide = 1 << 16;
constexpr uint64_t kMaxFlakes = uint64_t(1) << 30;
// The k-d tree splits flakes by n and by |J|, |J| scaled so that its range counts as much as the
// range of lobe extents it causes (about 6 sigma_h |J|).
constexpr float kJacobianSplitScale = 3.0f;

// One flake while the hierarchy is built.
struct FlakeRec {
  float n[2];
  float j[4];       // {dnx/dux, dnx/duy, dny/dux, dny/duy} per texel
  float jnorm;      // Frobenius norm of J (bounds its spectral norm), rounded up
  uint32_t fx, fy;  // fine grid coordinates
};

// The flakes of one leaf, eight lanes of each quantity (structure of arrays for the evaluator's
// four-lane loop). Positions are relative to the tile's origin, in texels.
struct Block {
  float nx[8], ny[8];
  float j0[8], j1[8], j2[8], j3[8];  // J
  float jxx[8], jxy[8], jyy[8];      // J J^T = {j0^2 + j1^2, j0 j2 + j1 j3, j2^2 + j3^2}
  float jdet[8];                     // det(J J^T) = (j0 j3 - j1 j2)^2
  float px[8], py[8];
};

struct Node {
  float lo[2], hi[2];  // bounds of n over the node's flakes
  float jmax;          // largest Frobenius norm of J over them
  uint32_t block;      // leaf: its block
  uint32_t count;      // flakes below the node
  uint32_t child;      // index of the first of two children; 0 for a leaf
};

// Nodes of the k-d tree over `count` flakes (the split rule of buildTree).
uint32_t treeNodes(uint32_t count) {
  return count <= uint32_t(kLeafFlakes) ? 1u : 1u + treeNodes(count / 2) + treeNodes(count - count / 2);
}
uint32_t treeLeaves(uint32_t count) {
  return count <= uint32_t(kLeafFlakes) ? 1u : treeLeaves(count / 2) + treeLeaves(count - count / 2);
}

// Constants of one footprint shared by every flake (Yan et al. 2016 closed form).
struct FootprintTerms {
  double ux, uy;           // footprint centre, texels (reduced into the map for repeating maps)
  double v;                // sigma_h^2 + sigma_p^2
  double a;                // sigma_h^2 / v: how far the lobe mean moves along J (u_Q - u_k)
  double b;                // sigma_h^2 sigma_p^2 / v: the J J^T share of the lobe covariance
  double inv2v;            // 1 / (2 v)
  double wnorm;            // A / (2 pi v)
  int64_t x0, x1, y0, y1;  // window of fine flake indices (unwrapped, inclusive)
  bool empty;
};

// A leaf reached by the traversal: its block, flake count and the footprint centre relative to
// the origin of its tile's periodic image (so u_Q - u_k = base - p_k).
struct LeafVisit {
  const Block* block;
  int count;
  double base_x, base_y;
};

}  // namespace

struct FlakeNdf::Impl {
  int width = 0, height = 0;  // texels
  int rate = 1;
  int fine_w = 0, fine_h = 0;
  bool repeat = true;
  double step = 1.0, area = 1.0, sigma_h2 = 0.0, sigma_r2 = 0.0, sigma_r = 0.0;
  int res = 128;
  int tiles_x = 0, tiles_y = 0;
  Array<Block> blocks;
  Array<uint32_t> slot;  // fine index (fy * fine_w + fx) -> block * 8 + lane
  Array<Node> nodes;
  Array<uint32_t> tile_root;  // node index of every tile's root

  RuntimeStatus build(const TexelSource& src, int rate_in, double sigma_r_in, int res_in);
  void buildFlakes(const float* normals, int tx, int ty, FlakeRec* out, uint32_t* count) const;
  void buildTree(uint32_t id, FlakeRec* f, uint32_t count, double origin_x, double origin_y, uint32_t* next_node,
                 uint32_t* next_block);
  bool terms(const Footprint& fp, FootprintTerms* t) const;
  double flakePosition(int64_t f) const { return (double(f) + 0.5) * step; }
  double tileOrigin(int64_t tile) const { return double(tile * kTile) * step; }
  // The lobe of lane i of a block for u_Q - u_k = (dx, dy).
  void lobeOf(const Block& k, int i, double dx, double dy, const FootprintTerms& t, flakes::Lobe* g) const {
    g->mx = double(k.nx[i]) + t.a * (double(k.j0[i]) * dx + double(k.j1[i]) * dy);
    g->my = double(k.ny[i]) + t.a * (double(k.j2[i]) * dx + double(k.j3[i]) * dy);
    g->cxx = sigma_r2 + t.b * double(k.jxx[i]);
    g->cxy = t.b * double(k.jxy[i]);
    g->cyy = sigma_r2 + t.b * double(k.jyy[i]);
  }
  // Calls visit(LeafVisit) for every leaf of the window's tiles that passes reach(node, dmax,
  // budget): dmax bounds |u_Q - u_k| over the tile, budget is kMaxExponent less the smallest
  // spatial exponent of the tile. Tiles beyond the truncation disk are skipped.
  template <typename Reach, typename Visit>
  void forEachLeaf(const FootprintTerms& t, Reach&& reach, Visit&& visit) const;
  // Calls visit(block, lane, dx, dy, spatial exponent) for every flake of the leaf within the
  // truncation disk (scalar paths: average, image).
  template <typename Visit>
  void forEachFlakeOf(const LeafVisit& leaf, const FootprintTerms& t, Visit&& visit) const;
  double evalAt(const FootprintTerms& t, double sx, double sy) const;
  double weightSum(const FootprintTerms& t, bool along_x) const;
  double mass(const FootprintTerms& t) const { return t.wnorm * weightSum(t, true) * weightSum(t, false); }
};

// The flakes of tile (tx, ty): position, n_k by interpolation and J_k by central differences of the
// interpolant, one texel on each side (the flake model of formats/SPEC.md 10.5).
void FlakeNdf::Impl::buildFlakes(const float* normals, int tx, int ty, FlakeRec* out, uint32_t* count) const {
  uint32_t c = 0;
  for (int fy = ty * kTile; fy < std::min(fine_h, (ty + 1) * kTile); ++fy) {
    for (int fx = tx * kTile; fx < std::min(fine_w, (tx + 1) * kTile); ++fx) {
      FlakeRec& k = out[c++];
      const double ux = flakePosition(fx), uy = flakePosition(fy);
      flakes::flakeAt(normals, width, height, repeat, ux, uy, k.n, k.j);
      double jj = 0.0;
      for (float j : k.j) jj += double(j) * j;
      k.jnorm = float(std::sqrt(jj) * (1.0 + 1e-6));
      k.fx = uint32_t(fx);
      k.fy = uint32_t(fy);
    }
  }
  *count = c;
}

RuntimeStatus FlakeNdf::Impl::build(const TexelSource& src, int rate_in, double sigma_r_in, int res_in) {
  width = src.width();
  height = src.height();
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide) return RuntimeStatus::kInvalidArgument;
  if (rate_in < 1 || rate_in > 16 || !(sigma_r_in > 0.0 && sigma_r_in <= 1.0) || res_in < 2 || res_in > 4096)
    return RuntimeStatus::kInvalidArgument;
  if (uint64_t(width) * uint64_t(height) * uint64_t(rate_in) * uint64_t(rate_in) > kMaxFlakes)
    return RuntimeStatus::kInvalidArgument;
  rate = rate_in;
  repeat = src.repeats();
  res = res_in;
  sigma_r = sigma_r_in;
  sigma_r2 = sigma_r * sigma_r;
  step = 1.0 / rate;
  area = step * step;
  const double sigma_h = step * 1.5 / std::sqrt(12.0);
  sigma_h2 = sigma_h * sigma_h;
  fine_w = width * rate;
  fine_h = height * rate;
  tiles_x = (fine_w + kTile - 1) / kTile;
  tiles_y = (fine_h + kTile - 1) / kTile;

  size_t node_count = 0, block_count = 0;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const uint32_t c = uint32_t(std::min(kTile, fine_w - tx * kTile) * std::min(kTile, fine_h - ty * kTile));
      node_count += treeNodes(c);
      block_count += treeLeaves(c);
    }
  }
  Array<float> normals;
  const size_t texels = size_t(width) * size_t(height);
  if (!normals.allocate(texels * 2) || !blocks.allocate(block_count) ||
      !slot.allocate(size_t(fine_w) * size_t(fine_h)) || !tile_root.allocate(size_t(tiles_x) * size_t(tiles_y)) ||
      !nodes.allocate(node_count))
    return RuntimeStatus::kOutOfMemory;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float* n = normals.data + (size_t(y) * size_t(width) + size_t(x)) * 2;
      src.normal(x, y, n);
      if (!std::isfinite(n[0]) || !std::isfinite(n[1])) return RuntimeStatus::kInvalidArgument;
    }
  }
  FlakeRec tile[kTile * kTile];
  uint32_t next_node = 0, next_block = 0;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      uint32_t count = 0;
      buildFlakes(normals.data, tx, ty, tile, &count);
      const uint32_t root = next_node++;
      tile_root.data[size_t(ty) * size_t(tiles_x) + size_t(tx)] = root;
      buildTree(root, tile, count, tileOrigin(tx), tileOrigin(ty), &next_node, &next_block);
    }
  }
  return RuntimeStatus::kOk;
}

// Builds node `id`, the k-d tree over f[0, count): splits at the median of the widest of n_x, n_y
// and the scaled |J| until at most kLeafFlakes remain; children are allocated as a pair from
// *next_node, leaves take the next block.
void FlakeNdf::Impl::buildTree(uint32_t id, FlakeRec* f, uint32_t count, double origin_x, double origin_y,
                               uint32_t* next_node, uint32_t* next_block) {
  Node node;
  node.lo[0] = node.lo[1] = 1e30f;
  node.hi[0] = node.hi[1] = -1e30f;
  node.jmax = 0.0f;
  float jmin = 1e30f;
  for (uint32_t i = 0; i < count; ++i) {
    for (int a = 0; a < 2; ++a) {
      node.lo[a] = std::min(node.lo[a], f[i].n[a]);
      node.hi[a] = std::max(node.hi[a], f[i].n[a]);
    }
    node.jmax = std::max(node.jmax, f[i].jnorm);
    jmin = std::min(jmin, f[i].jnorm);
  }
  node.count = count;
  node.child = 0;
  node.block = 0;
  if (count > uint32_t(kLeafFlakes)) {
    const float extent[3] = {node.hi[0] - node.lo[0], node.hi[1] - node.lo[1],
                             (node.jmax - jmin) * kJacobianSplitScale};
    const int axis = extent[2] > std::max(extent[0], extent[1]) ? 2 : (extent[0] >= extent[1] ? 0 : 1);
    auto key = [axis](const FlakeRec& p) { return axis == 2 ? p.jnorm : p.n[axis]; };
    const uint32_t half = count / 2;
    std::nth_element(f, f + half, f + count, [&key](const FlakeRec& p, const FlakeRec& q) {
      const float a = key(p), b = key(q);
      return a < b || (a == b && (p.fy < q.fy || (p.fy == q.fy && p.fx < q.fx)));
    });
    node.child = *next_node;
    *next_node += 2;
    buildTree(node.child, f, half, origin_x, origin_y, next_node, next_block);
    buildTree(node.child + 1, f + half, count - half, origin_x, origin_y, next_node, next_block);
  } else {
    node.block = (*next_block)++;
    Block& b = blocks.data[node.block];
    for (int i = 0; i < kLeafFlakes; ++i) {
      const bool used = uint32_t(i) < count;
      const FlakeRec k = used ? f[i] : FlakeRec{{0, 0}, {0, 0, 0, 0}, 0, 0, 0};
      b.nx[i] = k.n[0];
      b.ny[i] = k.n[1];
      b.j0[i] = k.j[0];
      b.j1[i] = k.j[1];
      b.j2[i] = k.j[2];
      b.j3[i] = k.j[3];
      b.jxx[i] = float(double(k.j[0]) * k.j[0] + double(k.j[1]) * k.j[1]);
      b.jxy[i] = float(double(k.j[0]) * k.j[2] + double(k.j[1]) * k.j[3]);
      b.jyy[i] = float(double(k.j[2]) * k.j[2] + double(k.j[3]) * k.j[3]);
      const double dj = double(k.j[0]) * k.j[3] - double(k.j[1]) * k.j[2];
      b.jdet[i] = float(dj * dj);
      b.px[i] = used ? float(flakePosition(k.fx) - origin_x) : kPaddingPosition;
      b.py[i] = used ? float(flakePosition(k.fy) - origin_y) : kPaddingPosition;
      if (used) slot.data[size_t(k.fy) * size_t(fine_w) + k.fx] = node.block * kLeafFlakes + uint32_t(i);
    }
  }
  nodes.data[id] = node;
}

bool FlakeNdf::Impl::terms(const Footprint& fp, FootprintTerms* t) const {
  const double sp2 = fp.sigma * fp.sigma;
  t->v = sigma_h2 + sp2;
  t->a = sigma_h2 / t->v;
  t->b = sigma_h2 * sp2 / t->v;
  t->inv2v = 0.5 / t->v;
  t->wnorm = area / (kTwoPi * t->v);
  t->ux = fp.x;
  t->uy = fp.y;
  if (repeat) {  // the flakes repeat with the map: reduce the centre into it
    t->ux -= format::NdfBlendAxis::floorOf(t->ux / width) * width;
    t->uy -= format::NdfBlendAxis::floorOf(t->uy / height) * height;
  }
  const double reach = kWindowSigmas * std::sqrt(t->v);
  const double fx0 = std::ceil((t->ux - reach) * rate - 0.5), fx1 = std::floor((t->ux + reach) * rate - 0.5);
  const double fy0 = std::ceil((t->uy - reach) * rate - 0.5), fy1 = std::floor((t->uy + reach) * rate - 0.5);
  if (!(fx1 - fx0 < double(kMaxFlakeWindow) && fy1 - fy0 < double(kMaxFlakeWindow))) return false;
  if (!(std::fabs(fx0) < 1e15 && std::fabs(fy0) < 1e15)) return false;  // a clamped map's far positions
  t->x0 = int64_t(fx0);
  t->x1 = int64_t(fx1);
  t->y0 = int64_t(fy0);
  t->y1 = int64_t(fy1);
  if (!repeat) {
    t->x0 = std::max<int64_t>(t->x0, 0);
    t->y0 = std::max<int64_t>(t->y0, 0);
    t->x1 = std::min<int64_t>(t->x1, fine_w - 1);
    t->y1 = std::min<int64_t>(t->y1, fine_h - 1);
  }
  t->empty = t->x0 > t->x1 || t->y0 > t->y1;
  return true;
}

template <typename Reach, typename Visit>
void FlakeNdf::Impl::forEachLeaf(const FootprintTerms& t, Reach&& reach, Visit&& visit) const {
  if (t.empty) return;
  auto floorDiv = [](int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  // |u_Q - u| over the flake positions [p0, p1] of a tile: largest and smallest.
  auto span = [](double q, double p0, double p1, double* dmax, double* dmin) {
    const double a = q - p0, b = q - p1;
    *dmax = std::max(std::fabs(a), std::fabs(b));
    *dmin = (a > 0.0) == (b > 0.0) ? std::min(std::fabs(a), std::fabs(b)) : 0.0;
  };
  uint32_t stack[64];
  for (int64_t py = floorDiv(t.y0, fine_h); py <= floorDiv(t.y1, fine_h); ++py) {
    const int64_t oy = py * fine_h;
    const int64_t ly0 = std::max<int64_t>(t.y0 - oy, 0), ly1 = std::min<int64_t>(t.y1 - oy, fine_h - 1);
    const double offy = double(oy) * step;
    for (int64_t px = floorDiv(t.x0, fine_w); px <= floorDiv(t.x1, fine_w); ++px) {
      const int64_t ox = px * fine_w;
      const int64_t lx0 = std::max<int64_t>(t.x0 - ox, 0), lx1 = std::min<int64_t>(t.x1 - ox, fine_w - 1);
      const double offx = double(ox) * step;
      for (int64_t ty = ly0 / kTile; ty <= ly1 / kTile; ++ty) {
        double dy, dy_min;
        span(t.uy, offy + flakePosition(std::max<int64_t>(ty * kTile, ly0)),
             offy + flakePosition(std::min<int64_t>(ty * kTile + kTile - 1, ly1)), &dy, &dy_min);
        for (int64_t tx = lx0 / kTile; tx <= lx1 / kTile; ++tx) {
          double dx, dx_min;
          span(t.ux, offx + flakePosition(std::max<int64_t>(tx * kTile, lx0)),
               offx + flakePosition(std::min<int64_t>(tx * kTile + kTile - 1, lx1)), &dx, &dx_min);
          // What the spatial weight leaves of the exponent budget for the nearest flake of the tile.
          const double budget = kMaxExponent - (dx_min * dx_min + dy_min * dy_min) * t.inv2v;
          if (budget < 0.0) continue;
          const double dmax = std::sqrt(dx * dx + dy * dy);
          const LeafVisit base{nullptr, 0, t.ux - offx - tileOrigin(tx), t.uy - offy - tileOrigin(ty)};
          int top = 0;
          stack[top++] = tile_root.data[size_t(ty) * size_t(tiles_x) + size_t(tx)];
          while (top > 0) {
            const Node& node = nodes.data[stack[--top]];
            if (!reach(node, dmax, budget)) continue;
            if (node.child != 0) {
              stack[top++] = node.child + 1;
              stack[top++] = node.child;
              continue;
            }
            LeafVisit leaf = base;
            leaf.block = &blocks.data[node.block];
            leaf.count = int(node.count);
            visit(leaf);
          }
        }
      }
    }
  }
}

template <typename Visit>
void FlakeNdf::Impl::forEachFlakeOf(const LeafVisit& leaf, const FootprintTerms& t, Visit&& visit) const {
  for (int i = 0; i < leaf.count; ++i) {
    const double dx = leaf.base_x - double(leaf.block->px[i]), dy = leaf.base_y - double(leaf.block->py[i]);
    const double spatial = (dx * dx + dy * dy) * t.inv2v;
    if (spatial <= kMaxExponent) visit(*leaf.block, i, dx, dy, spatial);
  }
}

double FlakeNdf::Impl::evalAt(const FootprintTerms& t, double sx, double sy) const {
  using flakes::F4;
  // Largest lobe variance and mean shift of a node: C_k <= (sigma_r^2 + b |J|^2) I and
  // |mu_k - n_k| <= a |J| |u_Q - u_k|.
  auto reach = [&](const Node& node, double dmax, double budget) {
    const double shift = double(node.jmax) * t.a * dmax;
    const double var = sigma_r2 + t.b * double(node.jmax) * double(node.jmax);
    const double ex = std::max(std::max(double(node.lo[0]) - shift - sx, sx - double(node.hi[0]) - shift), 0.0);
    const double ey = std::max(std::max(double(node.lo[1]) - shift - sy, sy - double(node.hi[1]) - shift), 0.0);
    return ex * ex + ey * ey <= 2.0 * budget * var;
  };
  // Four flakes at a time in float: s split into a float and its remainder, so that s - n_k keeps
  // double accuracy; det C from the expansion sr^4 + sr^2 b tr(J J^T) + b^2 det(J J^T), which does
  // not cancel for rank-1 Jacobians.
  const float sx_hi = float(sx), sy_hi = float(sy);
  const F4 sxh = F4::splat(sx_hi), sxl = F4::splat(float(sx - double(sx_hi)));
  const F4 syh = F4::splat(sy_hi), syl = F4::splat(float(sy - double(sy_hi)));
  const F4 a = F4::splat(float(t.a)), b = F4::splat(float(t.b)), inv2v = F4::splat(float(t.inv2v));
  const F4 sr2 = F4::splat(float(sigma_r2)), sr4 = F4::splat(float(sigma_r2 * sigma_r2));
  const F4 sr2b = F4::splat(float(sigma_r2 * t.b)), b2 = F4::splat(float(t.b * t.b));
  const F4 half = F4::splat(0.5f), two = F4::splat(2.0f), cutoff = F4::splat(float(kMaxExponent));
  double sum = 0.0;
  forEachLeaf(t, reach, [&](const LeafVisit& leaf) {
    const Block& k = *leaf.block;
    const F4 bx = F4::splat(float(leaf.base_x)), by = F4::splat(float(leaf.base_y));
    F4 acc = F4::splat(0.0f);
    for (int h = 0; h < leaf.count; h += 4) {
      const F4 dx = bx - F4::load(k.px + h), dy = by - F4::load(k.py + h);
      const F4 spatial = (dx * dx + dy * dy) * inv2v;
      const F4 ex = ((sxh - F4::load(k.nx + h)) + sxl) - a * (F4::load(k.j0 + h) * dx + F4::load(k.j1 + h) * dy);
      const F4 ey = ((syh - F4::load(k.ny + h)) + syl) - a * (F4::load(k.j2 + h) * dx + F4::load(k.j3 + h) * dy);
      const F4 jxx = F4::load(k.jxx + h), jyy = F4::load(k.jyy + h);
      const F4 cxx = sr2 + b * jxx, cxy = b * F4::load(k.jxy + h), cyy = sr2 + b * jyy;
      const F4 det = sr4 + sr2b * (jxx + jyy) + b2 * F4::load(k.jdet + h);
      const F4 q = (cyy * ex * ex - two * cxy * ex * ey + cxx * ey * ey) / det;
      const F4 e = spatial + half * q;
      if (!anyLess(e, cutoff)) continue;
      acc = acc + selectLess(e, cutoff, flakes::expNeg4(e) / sqrt(det));
    }
    float lanes[4];
    acc.store(lanes);
    sum += (double(lanes[0]) + double(lanes[1])) + (double(lanes[2]) + double(lanes[3]));
  });
  return sum * t.wnorm / kTwoPi;
}

// Sum of exp(-d^2 / 2v) over the window's flake positions along one axis (the footprint weights
// are separable: their total is wnorm times the product of the two sums).
double FlakeNdf::Impl::weightSum(const FootprintTerms& t, bool along_x) const {
  if (t.empty) return 0.0;
  const int64_t f0 = along_x ? t.x0 : t.y0, f1 = along_x ? t.x1 : t.y1;
  const double u = along_x ? t.ux : t.uy;
  double s = 0.0;
  for (int64_t f = f0; f <= f1; ++f) {
    const double d = u - flakePosition(f);
    s += std::exp(-d * d * t.inv2v);
  }
  return s;
}

FlakeNdf::FlakeNdf() = default;
FlakeNdf::~FlakeNdf() = default;

RuntimeStatus FlakeNdf::build(const TexelSource& source, int rate, double sigma_r, int resolution) {
  impl_.reset();
  auto impl = std::unique_ptr<Impl>(new (std::nothrow) Impl());
  if (!impl) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus s = impl->build(source, rate, sigma_r, resolution); s != RuntimeStatus::kOk) return s;
  impl_ = std::move(impl);
  return RuntimeStatus::kOk;
}

bool FlakeNdf::isBuilt() const { return impl_ != nullptr; }
int FlakeNdf::resolution() const { return impl_ ? impl_->res : 0; }
MapSize FlakeNdf::mapSize() const { return impl_ ? MapSize{impl_->width, impl_->height} : MapSize{}; }
MapWrap FlakeNdf::wrap() const { return impl_ && !impl_->repeat ? MapWrap::kClamp : MapWrap::kRepeat; }

FootprintRange FlakeNdf::footprintRange() const {
  FootprintRange r;
  // The largest footprint whose window (12 sqrt(v) texels across) fits kMaxFlakeWindow flakes.
  if (impl_) r.exact_max_sigma = std::floor(double(kMaxFlakeWindow - 2) / (2.0 * kWindowSigmas * impl_->rate));
  return r;
}
double FlakeNdf::sigmaR() const { return impl_ ? impl_->sigma_r : 0.0; }

using flakes::inSquare;
using flakes::validPoint;
using flakes::validRect;

RuntimeStatus FlakeNdf::eval(const Footprint& footprint, const SPoint& s, double* value) const {
  if (!impl_ || !value || !validFootprint(footprint) || !validPoint(s)) return RuntimeStatus::kInvalidArgument;
  FootprintTerms t;
  if (!impl_->terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  *value = inSquare(s) ? impl_->evalAt(t, s.x, s.y) : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdf::mass(const Footprint& footprint, double* value) const {
  if (!impl_ || !value || !validFootprint(footprint)) return RuntimeStatus::kInvalidArgument;
  FootprintTerms t;
  if (!impl_->terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  *value = impl_->mass(t);
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdf::pdf(const Footprint& footprint, const SPoint& s, double* value) const {
  if (!impl_ || !value || !validFootprint(footprint) || !validPoint(s)) return RuntimeStatus::kInvalidArgument;
  FootprintTerms t;
  if (!impl_->terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  const double m = impl_->mass(t);
  *value = (inSquare(s) && m > 0.0) ? impl_->evalAt(t, s.x, s.y) / m : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdf::average(const Footprint& footprint, const SRect& rect, double* value) const {
  if (!impl_ || !value || !validFootprint(footprint) || !validRect(rect)) return RuntimeStatus::kInvalidArgument;
  const Impl& m = *impl_;
  FootprintTerms t;
  if (!m.terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  const double x0 = std::max(rect.x0, -1.0), x1 = std::min(rect.x1, 1.0);
  const double y0 = std::max(rect.y0, -1.0), y1 = std::min(rect.y1, 1.0);
  double integral = 0.0;
  if (x1 > x0 && y1 > y0) {
    auto reach = [&](const Node& node, double dmax, double) {
      const double shift = double(node.jmax) * t.a * dmax;
      const double sd = std::sqrt(m.sigma_r2 + t.b * double(node.jmax) * double(node.jmax)) * 8.5;
      return double(node.hi[0]) + shift + sd > x0 &&
             double(node.lo[0]) - shift - sd<x1&& double(node.hi[1]) + shift + sd> y0 &&
             double(node.lo[1]) - shift - sd < y1;
    };
    m.forEachLeaf(t, reach, [&](const LeafVisit& leaf) {
      m.forEachFlakeOf(leaf, t, [&](const Block& k, int i, double dx, double dy, double spatial) {
        flakes::Lobe g;
        m.lobeOf(k, i, dx, dy, t, &g);
        const double p = flakes::lobeRectProbability(g, x0, x1, y0, y1);
        if (p > 0.0) integral += p * std::exp(-spatial);
      });
    });
    integral *= t.wnorm;
  }
  *value = integral / ((rect.x1 - rect.x0) * (rect.y1 - rect.y0));
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdf::addImage(const Footprint& footprint, double weight, float* out, size_t out_count) const {
  if (!impl_) return RuntimeStatus::kInvalidArgument;
  const Impl& m = *impl_;
  const int res = m.res;
  const size_t n = size_t(res) * size_t(res);
  if (!out || out_count < n || !validFootprint(footprint) || !std::isfinite(weight))
    return RuntimeStatus::kInvalidArgument;
  FootprintTerms t;
  if (!m.terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  const double bin = 2.0 / res;
  // Each lobe adds its probability over the bins, scaled to a density (divided by the bin area),
  // in the fixed order of the traversal.
  const double to_density = weight * t.wnorm / (bin * bin);
  auto all = [](const Node&, double, double) { return true; };
  m.forEachLeaf(t, all, [&](const LeafVisit& leaf) {
    m.forEachFlakeOf(leaf, t, [&](const Block& k, int i, double dx, double dy, double spatial) {
      flakes::Lobe g;
      m.lobeOf(k, i, dx, dy, t, &g);
      flakes::splatLobe(g, to_density * std::exp(-spatial), res, out);
    });
  });
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdf::sample(const Footprint& footprint, double u1, double u2, NdfSample* out) const {
  if (!impl_ || !out || !validFootprint(footprint) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  const Impl& m = *impl_;
  FootprintTerms t;
  if (!m.terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  const double sum_x = m.weightSum(t, true), sum_y = m.weightSum(t, false);
  const double total = t.wnorm * sum_x * sum_y;
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
  // The footprint weights are separable: a row by its weight, then a column; each uniform is
  // rescaled within the chosen interval and reused for the lobe.
  auto pick = [&](int64_t f0, int64_t f1, double centre, double u, double sum, double* rest) {
    double target = u * sum;
    int64_t f = f0;
    double g = 0.0;
    for (; f <= f1; ++f) {
      const double d = centre - m.flakePosition(f);
      g = std::exp(-d * d * t.inv2v);
      if (target < g || f == f1) break;
      target -= g;
    }
    *rest = g > 0.0 ? std::clamp(target / g, 0.0, 0.99999999999999989) : 0.5;
    return f;
  };
  double v1, v2;
  const int64_t fy = pick(t.y0, t.y1, t.uy, u1, sum_y, &v1);
  const int64_t fx = pick(t.x0, t.x1, t.ux, u2, sum_x, &v2);
  const int64_t gx = ((fx % m.fine_w) + m.fine_w) % m.fine_w, gy = ((fy % m.fine_h) + m.fine_h) % m.fine_h;
  const uint32_t where = m.slot.data[size_t(gy) * size_t(m.fine_w) + size_t(gx)];
  flakes::Lobe g;
  m.lobeOf(m.blocks.data[where / kLeafFlakes], int(where % kLeafFlakes), t.ux - m.flakePosition(fx),
           t.uy - m.flakePosition(fy), t, &g);
  // Box-Muller, then the Cholesky factor of the lobe covariance.
  const double radius = std::sqrt(-2.0 * std::log1p(-v1));
  const double z0 = radius * std::cos(kTwoPi * v2), z1 = radius * std::sin(kTwoPi * v2);
  const double l11 = std::sqrt(g.cxx), l21 = g.cxy / l11, l22 = std::sqrt(std::max(g.cyy - l21 * l21, 0.0));
  out->s.x = g.mx + l11 * z0;
  out->s.y = g.my + l21 * z0 + l22 * z1;
  out->pdf = inSquare(out->s) ? m.evalAt(t, out->s.x, out->s.y) / total : 0.0;
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
