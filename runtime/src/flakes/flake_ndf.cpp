// SPDX-License-Identifier: Apache-2.0
// The exact small-footprint P-NDF from a normal map's flakes (see flake_ndf.h).
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/flake_ndf.h>

#include "../heap_array.h"
#include "../pyramid_blend.h"
#include "flake_access.h"
#include "flake_model.h"
#include "float4.h"
#include "float8.h"
#include "gaussian_rect.h"
#include "point_queries.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::runtime {
namespace {

constexpr int kTile = flakes::kTileFlakes;            // flakes per side of a tile of the hierarchy
constexpr int kLeafFlakes = 8;                        // flakes per leaf of a tile (one block)
constexpr int kLeaves = kTile * kTile / kLeafFlakes;  // leaves of a full tile
constexpr double kWindowSigmas = kFlakeWindowSigmas;  // spatial truncation radius, in sqrt(v)
// A flake is left out when its spatial exponent |u_Q - u_k|^2 / 2v plus its lobe's exponent at s
// exceeds this: its contribution is below e^-18 of its own peak. The spatial part alone is the
// reference evaluator's truncation (a disk of 6 sqrt(v)).
constexpr double kMaxExponent = kWindowSigmas * kWindowSigmas / 2;
constexpr float kPaddingNormal = 1e15f;  // normal of the unused lanes of a block: no lobe reaches s
constexpr float kEmptyBox = 1e18f;       // normal bounds of unused leaves: lo = kEmptyBox, hi = -kEmptyBox
// Tiles whose leaves are tested together before their blocks are evaluated (the leaf bounds of a
// batch and then its blocks are prefetched, so that their cache misses overlap).
constexpr int kTileBatch = 16;
// The footprint weights along an axis follow a product recurrence, recomputed by exp every this
// many flakes (rounding grows with the square of the run: below 1e-13 relative).
constexpr int64_t kWeightRefresh = 16;
constexpr int kMaxSide = 1 << 16;
constexpr uint64_t kMaxFlakes = uint64_t(1) << 30;

// One flake while the hierarchy is built.
struct FlakeRec {
  float n[2];
  float j[4];       // {dnx/dux, dnx/duy, dny/dux, dny/duy} per texel
  float jnorm;      // Frobenius norm of J (bounds its spectral norm), rounded up
  uint32_t fx, fy;  // fine grid coordinates
};

// The flakes of one leaf, eight lanes of each quantity (structure of arrays for the evaluator's
// four-lane loop). Positions are the flake's fine index within its tile: u_k - tile origin =
// (l + 0.5) step. Unused lanes have normal kPaddingNormal, which no lobe test passes.
struct Block {
  float nx[8], ny[8];
  float j0[8], j1[8], j2[8], j3[8];  // J
  uint8_t lx[8], ly[8];
};

// Bounds of a tile's leaves for the four-lane reach test: normal box, largest Frobenius norm of
// J, and the box of the flake positions (relative to the tile's origin, texels). Unused leaves
// have an empty normal box that no test passes.
struct LeafBounds {
  float lo_x[kLeaves], lo_y[kLeaves], hi_x[kLeaves], hi_y[kLeaves];
  float jmax[kLeaves];
  // Largest (J J^T)_xx, (J J^T)_yy and u^T J J^T u for u = (1, 1) / sqrt 2 and (1, -1) / sqrt 2:
  // the lobes' variances along those directions are below sigma_r^2 + b times them.
  float jxx[kLeaves], jyy[kLeaves], jpp[kLeaves], jmm[kLeaves];
  float plo_x[kLeaves], plo_y[kLeaves], phi_x[kLeaves], phi_y[kLeaves];
};

// Bounds over a whole tile (dense, tested before its leaves are touched).
struct TileBound {
  float lo[2], hi[2];  // bounds of n over the tile's flakes
  float jmax;          // largest Frobenius norm of J over them
  uint32_t leaves;     // leaves in use (the first ones)
};

// The mask of the first `leaves` leaves of a tile.
inline uint32_t leafMask(uint32_t leaves) { return leaves >= 32 ? ~0u : (1u << leaves) - 1u; }

// Leaves of the k-d tree over `count` flakes (the split rule of buildLeaves).
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
  double spatial_cut;      // largest spatial exponent (kMaxExponent: the window of 6 sqrt(v))
  int64_t x0, x1, y0, y1;  // window of fine flake indices (unwrapped, inclusive)
  bool empty;
  const flakes::TileCut* cut = nullptr;  // when set, only the window's tiles inside the cut
};

// A tile of the window (forEachWindowTile): periodic image (px, py), tile (tx, ty) of that image,
// its flakes within the window [fx0, fx1] x [fy0, fy1] (indices within the image) and the image's
// first flake (ox, oy), so that a flake's unwrapped index is ox + fx.
struct WindowTile {
  int64_t px, py, tx, ty;
  int64_t fx0, fx1, fy0, fy1;
  int64_t ox, oy;
};

// A leaf reached by the traversal: its block and the footprint centre relative to
// the origin of its tile's periodic image (so u_Q - u_k = base - p_k).
struct LeafVisit {
  const Block* block;
  double base_x, base_y;
};

// The float constants of one point query shared by every lane of the kernel (flake_kernel.inc).
struct KernelTerms {
  float sxh, sxl, syh, syl;  // s split into a float and its remainder
  float a, b, inv2v, step;
  float sr2, sr4, sr2b, b2;  // sigma_r^2, sigma_r^4, sigma_r^2 b, b^2
  float keep_cut;            // the first pass's cutoff, kMaxExponent plus a margin
  float spatial_cut;         // lanes with a spatial exponent below it only
};

// The float constants of one point query's leaf reach test (reachMask in flake_kernel.inc).
struct LeafTerms {
  float sx, sy, sp, sm;  // s, s_x + s_y, s_x - s_y
  float a, b, inv2v;
  float budget_cut;     // kMaxExponent plus a margin against rounding
  float var_slack;      // 1 plus a margin: variances and shifts are widened by it
  float spatial_bound;  // the spatial truncation plus a margin
  float bound_sr2;      // sigma_r^2 widened
};

// Widest window (flakes) whose disk-row sums come from running sums on the stack (windowedMass,
// windowedPick): the windows of the lobes' exact level are at most about 140 flakes wide.
constexpr int kPrefixFlakes = FlakeNdfAccess::kPrefixFlakes;

// Lanes kept by the kernel's first pass, in traversal order (kLaneList of them at most, plus the
// room the branch-free writes and the padding to a whole vector take).
constexpr int kLaneList = 512;
struct LaneList {
  alignas(64) float spatial[kLaneList + 16];
  alignas(64) float num[kLaneList + 16];
  alignas(64) float det[kLaneList + 16];
  alignas(64) float value[kLaneList + 16];  // the second pass's lane values
};

namespace sse {
using V = flakes::F4;
#include "flake_kernel.inc"
}  // namespace sse

#if GLINTBAKE_FLAKES_AVX2
GLINTBAKE_FLAKES_AVX2_BEGIN
namespace avx2 {
using V = flakes::F8;
#include "flake_kernel.inc"
}  // namespace avx2
GLINTBAKE_FLAKES_AVX2_END
#else
namespace avx2 = sse;  // no AVX2 copy: both names are the SSE2 kernels
#endif

// The kernels of the processor: AVX2 where it has it (the same bits), else SSE2 or scalar.
int keepLanes(bool wide, const Block& k, const KernelTerms& c, float bx, float by, LaneList* list, int n) {
  return wide ? avx2::keepLanes(k, c, bx, by, list, n) : sse::keepLanes(k, c, bx, by, list, n);
}
void laneValues(bool wide, LaneList* list, int n, float cutoff) {
  if (wide)
    avx2::laneValues(list, n, cutoff);
  else
    sse::laneValues(list, n, cutoff);
}
uint32_t reachMask(bool wide, const LeafBounds& lb, const LeafTerms& c, float bx, float by) {
  return wide ? avx2::reachMask(lb, c, bx, by) : sse::reachMask(lb, c, bx, by);
}

}  // namespace

struct FlakeNdf::Impl {
  int width = 0, height = 0;  // texels
  int rate = 1;
  int fine_w = 0, fine_h = 0;
  bool repeat = true;
  double step = 1.0, area = 1.0, sigma_h2 = 0.0, sigma_r2 = 0.0, sigma_r = 0.0;
  int res = 128;
  int tiles_x = 0, tiles_y = 0;
  Array<TileBound> tile_bounds;   // per tile (row-major)
  Array<LeafBounds> leaf_bounds;  // per tile
  Array<Block> blocks;            // kLeaves per tile: tile * kLeaves + leaf
  Array<uint32_t> slot;           // fine index (fy * fine_w + fx) -> block * 8 + lane

  RuntimeStatus build(const TexelSource& src, int rate_in, double sigma_r_in, int res_in);
  void buildFlakes(const float* normals, int tx, int ty, FlakeRec* out, uint32_t* count) const;
  void buildLeaves(size_t tile, FlakeRec* f, uint32_t count, int tx, int ty, uint32_t* next_leaf);
  // The constants of a footprint, with the spatial truncation at window_sigmas sqrt(v) (a disk).
  bool terms(const Footprint& fp, FootprintTerms* t, double window_sigmas = kWindowSigmas) const;
  double flakePosition(int64_t f) const { return (double(f) + 0.5) * step; }
  double tileOrigin(int64_t tile) const { return double(tile * kTile) * step; }
  // Position of a flake within its tile, as the four-lane evaluator computes it.
  float localPosition(uint8_t l) const { return (float(l) + 0.5f) * float(step); }
  // The lobe of lane i of a block for u_Q - u_k = (dx, dy).
  void lobeOf(const Block& k, int i, double dx, double dy, const FootprintTerms& t, flakes::Lobe* g) const {
    const double j0 = k.j0[i], j1 = k.j1[i], j2 = k.j2[i], j3 = k.j3[i];
    g->mx = double(k.nx[i]) + t.a * (j0 * dx + j1 * dy);
    g->my = double(k.ny[i]) + t.a * (j2 * dx + j3 * dy);
    g->cxx = sigma_r2 + t.b * (j0 * j0 + j1 * j1);
    g->cxy = t.b * (j0 * j2 + j1 * j3);
    g->cyy = sigma_r2 + t.b * (j2 * j2 + j3 * j3);
  }
  // Calls visit(LeafVisit) for every leaf of the window's tiles that passes both tests:
  // tile(bound, dmax2) on the tile's bounds (dmax2 bounds |u_Q - u_k|^2 over the tile), then
  // leaves(bounds, base_x, base_y), a mask of the tile's leaves to visit (base = u_Q - the origin
  // of the tile's periodic image). Tiles beyond the truncation disk are skipped. The tiles of a
  // batch are tested before their leaves are visited, in the order of the window.
  template <typename TileTest, typename LeafTest, typename Visit>
  void forEachLeaf(const FootprintTerms& t, TileTest&& tile, LeafTest&& leaves, Visit&& visit) const;
  // Calls visit(WindowTile) for every tile that overlaps the window's box, in the order of the
  // window (rows of periodic images, then rows of tiles), but for the tiles outside t.cut when
  // it is set.
  template <typename Visit>
  void forEachWindowTile(const FootprintTerms& t, Visit&& visit) const;
  // The footprint weights' sum over the flakes of a tile: the product of the two axes' sums.
  static double tileWeight(const FootprintTerms& t, const WindowTile& w, const double* col, const double* row) {
    return (col[w.ox + w.fx1 + 1 - t.x0] - col[w.ox + w.fx0 - t.x0]) *
           (row[w.oy + w.fy1 + 1 - t.y0] - row[w.oy + w.fy0 - t.y0]);
  }
  // Calls visit(block, lane, dx, dy, spatial exponent) for every flake of the leaf within the
  // truncation disk (scalar paths: average, image).
  template <typename Visit>
  void forEachFlakeOf(const LeafVisit& leaf, const FootprintTerms& t, Visit&& visit) const;
  // The P-NDF at s. With inner non-null, also the sum over the flakes whose spatial exponent is
  // below inner_cut alone (the eval of a narrower window, from the same lane values).
  double evalAt(const FootprintTerms& t, double sx, double sy, float inner_cut = 0.0f, double* inner = nullptr) const;
  // The footprint weights exp(-d^2 / 2v) of the window's flake positions along one axis, in order,
  // passed to visit(index, weight) until it returns false (a recurrence of two products per
  // flake, refreshed by exp every kWeightRefresh flakes).
  template <typename Visit>
  void forEachWeight(const FootprintTerms& t, bool along_x, Visit&& visit) const;
  template <typename Visit>
  void forEachWeightIn(double u, int64_t f0, int64_t f1, double c, Visit&& visit) const;
  // The rows of the truncation disk (spatial exponent below t.spatial_cut): visit(fy, row
  // weight, x0, x1) with the row's flakes [x0, x1], until it returns false.
  template <typename Visit>
  void forEachDiskRow(const FootprintTerms& t, Visit&& visit) const;
  double diskRowSum(const FootprintTerms& t, int64_t x0, int64_t x1) const;
  // The running sums of the footprint weights along x over the window, prefix[i] = the sum over
  // flakes t.x0 .. t.x0 + i - 1 (i = 0 .. width), so that a disk row's sum is one difference;
  // false (nothing written) when the window is wider than kPrefixFlakes.
  bool columnPrefix(const FootprintTerms& t, double* prefix) const { return axisPrefix(t, true, prefix); }
  // The same along either axis (rows: prefix[i] sums flakes t.y0 .. t.y0 + i - 1).
  bool axisPrefix(const FootprintTerms& t, bool along_x, double* prefix) const;
  // A disk row's sum of weights: from the running sums when columnPrefix wrote them (prefix not
  // null), else added up flake by flake.
  double rowSum(const FootprintTerms& t, const double* prefix, int64_t x0, int64_t x1) const {
    if (!prefix) return diskRowSum(t, x0, x1);
    return x1 < x0 ? 0.0 : prefix[x1 + 1 - t.x0] - prefix[x0 - t.x0];
  }
  double weightSum(const FootprintTerms& t, bool along_x) const;
  double massOf(const FootprintTerms& t) const { return t.wnorm * weightSum(t, true) * weightSum(t, false); }
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

  const size_t tile_count = size_t(tiles_x) * size_t(tiles_y);
  Array<float> normals;
  const size_t texels = size_t(width) * size_t(height);
  if (!normals.allocate(texels * 2) || !blocks.allocate(tile_count * kLeaves) ||
      !slot.allocate(size_t(fine_w) * size_t(fine_h)) || !tile_bounds.allocate(tile_count) ||
      !leaf_bounds.allocate(tile_count))
    return RuntimeStatus::kOutOfMemory;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float* n = normals.data + (size_t(y) * size_t(width) + size_t(x)) * 2;
      src.normal(x, y, n);
      if (!std::isfinite(n[0]) || !std::isfinite(n[1])) return RuntimeStatus::kInvalidArgument;
    }
  }
  FlakeRec tile[kTile * kTile];
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      uint32_t count = 0;
      buildFlakes(normals.data, tx, ty, tile, &count);
      const size_t index = size_t(ty) * size_t(tiles_x) + size_t(tx);
      LeafBounds& lb = leaf_bounds.data[index];
      for (int i = 0; i < kLeaves; ++i) {
        lb.lo_x[i] = lb.lo_y[i] = kEmptyBox;
        lb.hi_x[i] = lb.hi_y[i] = -kEmptyBox;
        lb.jmax[i] = lb.plo_x[i] = lb.plo_y[i] = lb.phi_x[i] = lb.phi_y[i] = 0.0f;
        lb.jxx[i] = lb.jyy[i] = lb.jpp[i] = lb.jmm[i] = 0.0f;
      }
      uint32_t leaves = 0;
      buildLeaves(index, tile, count, tx, ty, &leaves);
      TileBound& tb = tile_bounds.data[index];
      tb.lo[0] = tb.lo[1] = kEmptyBox;
      tb.hi[0] = tb.hi[1] = -kEmptyBox;
      tb.jmax = 0.0f;
      tb.leaves = leaves;
      for (uint32_t i = 0; i < leaves; ++i) {
        tb.lo[0] = std::min(tb.lo[0], lb.lo_x[i]);
        tb.lo[1] = std::min(tb.lo[1], lb.lo_y[i]);
        tb.hi[0] = std::max(tb.hi[0], lb.hi_x[i]);
        tb.hi[1] = std::max(tb.hi[1], lb.hi_y[i]);
        tb.jmax = std::max(tb.jmax, lb.jmax[i]);
      }
      for (uint32_t i = leaves; i < uint32_t(kLeaves); ++i) {  // unused blocks of an edge tile
        Block& b = blocks.data[index * kLeaves + i];
        for (int l = 0; l < kLeafFlakes; ++l) {
          b.nx[l] = b.ny[l] = kPaddingNormal;
          b.j0[l] = b.j1[l] = b.j2[l] = b.j3[l] = 0.0f;
          b.lx[l] = b.ly[l] = 0;
        }
      }
    }
  }
  return RuntimeStatus::kOk;
}

// The leaves of a tile over f[0, count): halves at the median position along the longer side of
// the flakes' box (x on a tie) until at most kLeafFlakes remain, so that a full tile's leaves are
// blocks of 2 x 4 flakes; leaves take the tile's blocks in depth-first order, with their bounds.
// Leaves small in position let the reach test drop the flakes outside the footprint's window,
// which at 1 texel is most of a tile; neighbouring flakes have close normals on smooth maps. Per
// eval on the README's 1024^2 leather and curved scratches and the 512^2 sharp flakes, against
// leaves grouped by a k-d tree over n and |J| within the tile: 0.63 / 0.67 / 0.88x the leaves at
// 1 texel, 0.95 / 0.90 / 1.09x at 4 and 0.94 / 0.89 / 1.09x at 8 (the same flakes kept).
void FlakeNdf::Impl::buildLeaves(size_t tile, FlakeRec* f, uint32_t count, int tx, int ty, uint32_t* next_leaf) {
  if (count > uint32_t(kLeafFlakes)) {
    uint32_t flo[2] = {~0u, ~0u}, fhi[2] = {0u, 0u};
    for (uint32_t i = 0; i < count; ++i) {
      flo[0] = std::min(flo[0], f[i].fx);
      fhi[0] = std::max(fhi[0], f[i].fx);
      flo[1] = std::min(flo[1], f[i].fy);
      fhi[1] = std::max(fhi[1], f[i].fy);
    }
    const bool along_x = fhi[0] - flo[0] >= fhi[1] - flo[1];
    const uint32_t half = count / 2;
    std::nth_element(f, f + half, f + count, [along_x](const FlakeRec& p, const FlakeRec& q) {
      return along_x ? (p.fx < q.fx || (p.fx == q.fx && p.fy < q.fy)) : (p.fy < q.fy || (p.fy == q.fy && p.fx < q.fx));
    });
    buildLeaves(tile, f, half, tx, ty, next_leaf);
    buildLeaves(tile, f + half, count - half, tx, ty, next_leaf);
    return;
  }
  float lo[2] = {1e30f, 1e30f}, hi[2] = {-1e30f, -1e30f}, jmax = 0.0f;
  for (uint32_t i = 0; i < count; ++i) {
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], f[i].n[a]);
      hi[a] = std::max(hi[a], f[i].n[a]);
    }
    jmax = std::max(jmax, f[i].jnorm);
  }
  const uint32_t leaf = (*next_leaf)++;
  const uint32_t block = uint32_t(tile * kLeaves) + leaf;
  Block& b = blocks.data[block];
  LeafBounds& lb = leaf_bounds.data[tile];
  lb.lo_x[leaf] = lo[0];
  lb.lo_y[leaf] = lo[1];
  lb.hi_x[leaf] = hi[0];
  lb.hi_y[leaf] = hi[1];
  lb.jmax[leaf] = jmax;
  double var[4] = {0.0, 0.0, 0.0, 0.0};
  for (uint32_t i = 0; i < count; ++i) {
    const double j0 = f[i].j[0], j1 = f[i].j[1], j2 = f[i].j[2], j3 = f[i].j[3];
    const double xx = j0 * j0 + j1 * j1, yy = j2 * j2 + j3 * j3, xy = j0 * j2 + j1 * j3;
    const double along[4] = {xx, yy, 0.5 * (xx + yy) + xy, 0.5 * (xx + yy) - xy};
    for (int d = 0; d < 4; ++d) var[d] = std::max(var[d], along[d]);
  }
  lb.jxx[leaf] = float(var[0] * (1.0 + 1e-5));
  lb.jyy[leaf] = float(var[1] * (1.0 + 1e-5));
  lb.jpp[leaf] = float(var[2] * (1.0 + 1e-5));
  lb.jmm[leaf] = float(var[3] * (1.0 + 1e-5));
  float plo[2] = {1e30f, 1e30f}, phi[2] = {-1e30f, -1e30f};
  for (int i = 0; i < kLeafFlakes; ++i) {
    const bool used = uint32_t(i) < count;
    const FlakeRec k = used ? f[i] : FlakeRec{{kPaddingNormal, kPaddingNormal}, {0, 0, 0, 0}, 0, 0, 0};
    b.nx[i] = k.n[0];
    b.ny[i] = k.n[1];
    b.j0[i] = k.j[0];
    b.j1[i] = k.j[1];
    b.j2[i] = k.j[2];
    b.j3[i] = k.j[3];
    b.lx[i] = used ? uint8_t(k.fx - uint32_t(tx * kTile)) : 0;
    b.ly[i] = used ? uint8_t(k.fy - uint32_t(ty * kTile)) : 0;
    if (!used) continue;
    const float p[2] = {localPosition(b.lx[i]), localPosition(b.ly[i])};
    for (int a = 0; a < 2; ++a) {
      plo[a] = std::min(plo[a], p[a]);
      phi[a] = std::max(phi[a], p[a]);
    }
    slot.data[size_t(k.fy) * size_t(fine_w) + k.fx] = block * kLeafFlakes + uint32_t(i);
  }
  lb.plo_x[leaf] = plo[0];
  lb.plo_y[leaf] = plo[1];
  lb.phi_x[leaf] = phi[0];
  lb.phi_y[leaf] = phi[1];
}

bool FlakeNdf::Impl::terms(const Footprint& fp, FootprintTerms* t, double window_sigmas) const {
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
  t->spatial_cut = window_sigmas * window_sigmas / 2;
  const double reach = window_sigmas * std::sqrt(t->v);
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

template <typename Visit>
void FlakeNdf::Impl::forEachWindowTile(const FootprintTerms& t, Visit&& visit) const {
  if (t.empty) return;
  auto floorDiv = [](int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  WindowTile w;
  for (w.py = floorDiv(t.y0, fine_h); w.py <= floorDiv(t.y1, fine_h); ++w.py) {
    w.oy = w.py * fine_h;
    const int64_t ly0 = std::max<int64_t>(t.y0 - w.oy, 0), ly1 = std::min<int64_t>(t.y1 - w.oy, fine_h - 1);
    for (w.px = floorDiv(t.x0, fine_w); w.px <= floorDiv(t.x1, fine_w); ++w.px) {
      w.ox = w.px * fine_w;
      const int64_t lx0 = std::max<int64_t>(t.x0 - w.ox, 0), lx1 = std::min<int64_t>(t.x1 - w.ox, fine_w - 1);
      // The centre relative to this image's origin, as the clustered lobes' cut computes it.
      const double cx = t.ux - double(w.px) * width, cy = t.uy - double(w.py) * height;
      for (w.ty = ly0 / kTile; w.ty <= ly1 / kTile; ++w.ty) {
        w.fy0 = std::max<int64_t>(w.ty * kTile, ly0);
        w.fy1 = std::min<int64_t>(w.ty * kTile + kTile - 1, ly1);
        for (w.tx = lx0 / kTile; w.tx <= lx1 / kTile; ++w.tx) {
          if (t.cut) {
            double bx, by, dx, dy;
            flakes::tileGap(cx, cy, w.tx, w.ty, t.cut->side, &bx, &by, &dx, &dy);
            if (!(dx * dx + dy * dy < t.cut->limit2)) continue;
          }
          w.fx0 = std::max<int64_t>(w.tx * kTile, lx0);
          w.fx1 = std::min<int64_t>(w.tx * kTile + kTile - 1, lx1);
          visit(w);
        }
      }
    }
  }
}

template <typename TileTest, typename LeafTest, typename Visit>
void FlakeNdf::Impl::forEachLeaf(const FootprintTerms& t, TileTest&& tile, LeafTest&& leaves, Visit&& visit) const {
  if (t.empty) return;
  // |u_Q - u| over the flake positions [p0, p1] of a tile: largest and smallest.
  auto span = [](double q, double p0, double p1, double* dmax, double* dmin) {
    const double a = q - p0, b = q - p1;
    *dmax = std::max(std::fabs(a), std::fabs(b));
    *dmin = (a > 0.0) == (b > 0.0) ? std::min(std::fabs(a), std::fabs(b)) : 0.0;
  };
  // A batch of tiles that passed their tile test, their leaf bounds prefetched; then the leaves
  // of the batch that pass, their blocks prefetched, visited in order.
  struct TileVisit {
    size_t index;
    double base_x, base_y;
  };
  TileVisit batch[kTileBatch];
  LeafVisit reached[kTileBatch * kLeaves];
  int batched = 0;
  // Blocks are prefetched this many leaves ahead of the one visited.
  constexpr int kAhead = 6;
  auto fetch = [&](const LeafVisit& leaf) {
    const char* bytes = reinterpret_cast<const char*>(leaf.block);
    for (size_t o = 0; o < sizeof(Block); o += 64) flakes::prefetch(bytes + o);
    flakes::prefetch(bytes + sizeof(Block) - 1);
  };
  auto flush = [&] {
    int count = 0;
    for (int i = 0; i < batched; ++i) {
      const TileVisit& v = batch[i];
      const uint32_t mask = leaves(leaf_bounds.data[v.index], tile_bounds.data[v.index], v.base_x, v.base_y);
      for (int leaf = 0; leaf < kLeaves; ++leaf) {
        if (((mask >> leaf) & 1u) == 0) continue;
        reached[count] = LeafVisit{&blocks.data[v.index * kLeaves + size_t(leaf)], v.base_x, v.base_y};
        if (count < kAhead) fetch(reached[count]);
        ++count;
      }
    }
    for (int i = 0; i < count; ++i) {
      if (i + kAhead < count) fetch(reached[i + kAhead]);
      visit(reached[i]);
    }
    batched = 0;
  };
  forEachWindowTile(t, [&](const WindowTile& w) {
    const double offx = double(w.ox) * step, offy = double(w.oy) * step;
    double dx, dx_min, dy, dy_min;
    span(t.uy, offy + flakePosition(w.fy0), offy + flakePosition(w.fy1), &dy, &dy_min);
    span(t.ux, offx + flakePosition(w.fx0), offx + flakePosition(w.fx1), &dx, &dx_min);
    // Skip the tile when its nearest flake lies beyond the truncation disk or has a spatial
    // exponent above the whole budget.
    const double spatial_min = (dx_min * dx_min + dy_min * dy_min) * t.inv2v;
    if (spatial_min > t.spatial_cut || spatial_min > kMaxExponent) return;
    const size_t index = size_t(w.ty) * size_t(tiles_x) + size_t(w.tx);
    if (!tile(tile_bounds.data[index], dx * dx + dy * dy)) return;
    const char* bytes = reinterpret_cast<const char*>(&leaf_bounds.data[index]);
    for (size_t o = 0; o < sizeof(LeafBounds); o += 64) flakes::prefetch(bytes + o);
    flakes::prefetch(bytes + sizeof(LeafBounds) - 1);
    batch[batched++] = TileVisit{index, t.ux - offx - tileOrigin(w.tx), t.uy - offy - tileOrigin(w.ty)};
    if (batched == kTileBatch) flush();
  });
  flush();
}

template <typename Visit>
void FlakeNdf::Impl::forEachFlakeOf(const LeafVisit& leaf, const FootprintTerms& t, Visit&& visit) const {
  const Block& k = *leaf.block;
  for (int i = 0; i < kLeafFlakes; ++i) {
    if (k.nx[i] == kPaddingNormal) continue;
    const double dx = leaf.base_x - double(localPosition(k.lx[i])), dy = leaf.base_y - double(localPosition(k.ly[i]));
    const double spatial = (dx * dx + dy * dy) * t.inv2v;
    if (spatial <= t.spatial_cut) visit(k, i, dx, dy, spatial);
  }
}

double FlakeNdf::Impl::evalAt(const FootprintTerms& t, double sx, double sy, float inner_cut, double* inner) const {
  // No test of a whole tile's bounds against s (its normal box widened by the largest mean shift,
  // against its largest variance): the leaves' own test below decides, and the tile test skipped
  // too few tiles to pay for itself (eval 0.85-0.96x the time without it at 4-8 texels on the
  // README's leather, curved scratches and sharp flakes, the same lanes kept in the same order).
  // The tiles beyond the truncation disk are still skipped by forEachLeaf.
  auto tile = [](const TileBound&, double) { return true; };
  // The reach test per leaf (reachMask), in float from each leaf's box of positions, normals,
  // largest |J| and variances; the budget and variance widened against float rounding.
  LeafTerms lt;
  lt.sx = float(sx);
  lt.sy = float(sy);
  lt.sp = float(sx + sy);
  lt.sm = float(sx - sy);
  lt.a = float(t.a);
  lt.b = float(t.b);
  lt.inv2v = float(t.inv2v);
  lt.budget_cut = float(kMaxExponent) + 1e-3f;
  lt.var_slack = 1.0f + 1e-4f;
  lt.spatial_bound = float(t.spatial_cut) + 1e-3f;
  lt.bound_sr2 = float(sigma_r2) * (1.0f + 1e-4f);
  const bool wide = flakes::hasAvx2();
  auto leaves = [&](const LeafBounds& lb, const TileBound& tb, double base_x, double base_y) {
    return reachMask(wide, lb, lt, float(base_x), float(base_y)) & leafMask(tb.leaves);
  };
  // The kernel (flake_kernel.inc): s split into a float and its remainder, so that s - n_k keeps
  // double accuracy; det C from the expansion sr^4 + sr^2 b tr(J J^T) + b^2 det(J J^T), which does
  // not cancel for rank-1 Jacobians. The lanes kept by its first pass are evaluated and summed
  // (in double, four running sums in a fixed order) whenever the list fills up, and at the end.
  KernelTerms c;
  c.sxh = float(sx);
  c.sxl = float(sx - double(c.sxh));
  c.syh = float(sy);
  c.syl = float(sy - double(c.syh));
  c.a = float(t.a);
  c.b = float(t.b);
  c.inv2v = float(t.inv2v);
  c.step = float(step);
  c.sr2 = float(sigma_r2);
  c.sr4 = float(sigma_r2 * sigma_r2);
  c.sr2b = float(sigma_r2 * t.b);
  c.b2 = float(t.b * t.b);
  c.keep_cut = float(kMaxExponent) + 0.01f;
  c.spatial_cut = float(t.spatial_cut);
  LaneList list;
  int n = 0;
  double sums[4] = {0.0, 0.0, 0.0, 0.0};
  double inner_sum = 0.0;
  auto drain = [&] {
    const int padded = (n + 15) & ~15;
    for (int i = n; i < padded; ++i) {
      list.spatial[i] = 1e30f;
      list.num[i] = 0.0f;
      list.det[i] = 1.0f;
    }
    laneValues(wide, &list, padded, float(kMaxExponent));
    for (int i = 0; i < n; i += 4) {
      sums[0] += double(list.value[i]);
      sums[1] += double(list.value[i + 1]);
      sums[2] += double(list.value[i + 2]);
      sums[3] += double(list.value[i + 3]);
    }
    if (inner) {
      for (int i = 0; i < n; ++i)
        if (list.spatial[i] < inner_cut) inner_sum += double(list.value[i]);
    }
    n = 0;
  };
  forEachLeaf(t, tile, leaves, [&](const LeafVisit& leaf) {
    n = keepLanes(wide, *leaf.block, c, float(leaf.base_x), float(leaf.base_y), &list, n);
    if (n > kLaneList - kLeafFlakes) drain();
  });
  drain();
  if (inner) *inner = inner_sum * t.wnorm / kTwoPi;
  return ((sums[0] + sums[1]) + (sums[2] + sums[3])) * t.wnorm / kTwoPi;
}

template <typename Visit>
void FlakeNdf::Impl::forEachWeightIn(double u, int64_t f0, int64_t f1, double c, Visit&& visit) const {
  // With d = u - p_f: exp(-(d - step)^2 c) = exp(-d^2 c) exp((2 d step - step^2) c), and that
  // ratio shrinks by exp(-2 step^2 c) per flake.
  const double shrink = std::exp(-2.0 * step * step * c);
  double g = 0.0, ratio = 0.0;
  for (int64_t f = f0; f <= f1; ++f) {
    if ((f - f0) % kWeightRefresh == 0) {
      const double d = u - flakePosition(f);
      g = std::exp(-d * d * c);
      ratio = std::exp((2.0 * d * step - step * step) * c);
    }
    if (!visit(f, g)) return;
    g *= ratio;
    ratio *= shrink;
  }
}

template <typename Visit>
void FlakeNdf::Impl::forEachWeight(const FootprintTerms& t, bool along_x, Visit&& visit) const {
  if (t.empty) return;
  forEachWeightIn(along_x ? t.ux : t.uy, along_x ? t.x0 : t.y0, along_x ? t.x1 : t.y1, t.inv2v, visit);
}

template <typename Visit>
void FlakeNdf::Impl::forEachDiskRow(const FootprintTerms& t, Visit&& visit) const {
  if (t.empty) return;
  const double r2 = 2.0 * t.spatial_cut * t.v;
  forEachWeightIn(t.uy, t.y0, t.y1, t.inv2v, [&](int64_t fy, double gy) {
    const double dy = t.uy - flakePosition(fy);
    const double half_width = std::sqrt(std::max(r2 - dy * dy, 0.0));
    int64_t x0 = int64_t(std::ceil((t.ux - half_width) * rate - 0.5));
    int64_t x1 = int64_t(std::floor((t.ux + half_width) * rate - 0.5));
    x0 = std::max(x0, t.x0);
    x1 = std::min(x1, t.x1);
    return visit(fy, gy, x0, x1);
  });
}

double FlakeNdf::Impl::diskRowSum(const FootprintTerms& t, int64_t x0, int64_t x1) const {
  double s = 0.0;
  forEachWeightIn(t.ux, x0, x1, t.inv2v, [&](int64_t, double g) {
    s += g;
    return true;
  });
  return s;
}

bool FlakeNdf::Impl::axisPrefix(const FootprintTerms& t, bool along_x, double* prefix) const {
  const int64_t f0 = along_x ? t.x0 : t.y0, f1 = along_x ? t.x1 : t.y1;
  if (t.empty || f1 - f0 + 1 > kPrefixFlakes) return false;
  double sum = 0.0;
  prefix[0] = 0.0;
  forEachWeightIn(along_x ? t.ux : t.uy, f0, f1, t.inv2v, [&](int64_t f, double g) {
    sum += g;
    prefix[f - f0 + 1] = sum;
    return true;
  });
  return true;
}

// Sum of exp(-d^2 / 2v) over the window's flake positions along one axis (the footprint weights
// are separable: their total is wnorm times the product of the two sums).
double FlakeNdf::Impl::weightSum(const FootprintTerms& t, bool along_x) const {
  double s = 0.0;
  forEachWeight(t, along_x, [&](int64_t, double g) {
    s += g;
    return true;
  });
  return s;
}

namespace flakes {
std::atomic<bool>& portableKernelsOnly() {
  static std::atomic<bool> only{false};
  return only;
}
}  // namespace flakes

RuntimeStatus FlakeNdfAccess::windowedEval(const FlakeNdf& f, const Footprint& fp, const SPoint& s,
                                           double window_sigmas, double* value, const flakes::TileCut* cut) {
  if (!f.impl_ || !value || !validFootprint(fp) || !finitePoint(s)) return RuntimeStatus::kInvalidArgument;
  FootprintTerms t;
  if (!f.impl_->terms(fp, &t, window_sigmas)) return RuntimeStatus::kInvalidArgument;
  t.cut = cut;
  *value = flakes::inSquare(s) ? f.impl_->evalAt(t, s.x, s.y) : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdfAccess::evalWithInnerWindow(const FlakeNdf& f, const Footprint& fp, const SPoint& s,
                                                  double inner_window_sigmas, double outer_window_sigmas, double* value,
                                                  double* inner) {
  if (!f.impl_ || !value || !inner || !validFootprint(fp) || !finitePoint(s) ||
      !(inner_window_sigmas > 0.0 && inner_window_sigmas <= outer_window_sigmas &&
        outer_window_sigmas <= kWindowSigmas))
    return RuntimeStatus::kInvalidArgument;
  FootprintTerms t;
  if (!f.impl_->terms(fp, &t, outer_window_sigmas)) return RuntimeStatus::kInvalidArgument;
  *value = *inner = 0.0;
  // The lanes a window of inner_window_sigmas keeps: spatial exponent below its cut, as in
  // windowedEval's kernel (float comparison).
  const float inner_cut = float(inner_window_sigmas * inner_window_sigmas / 2);
  if (flakes::inSquare(s)) *value = f.impl_->evalAt(t, s.x, s.y, inner_cut, inner);
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdfAccess::windowedMass(const FlakeNdf& f, const Footprint& fp, double window_sigmas, double* value,
                                           const flakes::TileCut* cut) {
  if (!f.impl_ || !value || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  const FlakeNdf::Impl& m = *f.impl_;
  FootprintTerms t;
  if (!m.terms(fp, &t, window_sigmas)) return RuntimeStatus::kInvalidArgument;
  double sum = 0.0;
  if (cut) {  // tile by tile, from the running sums along both axes
    t.cut = cut;
    double col[kPrefixFlakes + 1], row[kPrefixFlakes + 1];
    if (!t.empty && !(m.axisPrefix(t, true, col) && m.axisPrefix(t, false, row)))
      return RuntimeStatus::kInvalidArgument;
    m.forEachWindowTile(t, [&](const WindowTile& w) { sum += FlakeNdf::Impl::tileWeight(t, w, col, row); });
    *value = t.wnorm * sum;
    return RuntimeStatus::kOk;
  }
  double buffer[kPrefixFlakes + 1];
  const double* prefix = m.columnPrefix(t, buffer) ? buffer : nullptr;
  m.forEachDiskRow(t, [&](int64_t, double gy, int64_t x0, int64_t x1) {
    sum += gy * m.rowSum(t, prefix, x0, x1);
    return true;
  });
  *value = t.wnorm * sum;
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdfAccess::windowedPick(const FlakeNdf& f, const Footprint& fp, double window_sigmas, double u1,
                                           double u2, double mass, flakes::Lobe* lobe, double* v1, double* v2,
                                           const flakes::TileCut* cut) {
  if (!f.impl_ || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  const FlakeNdf::Impl& m = *f.impl_;
  FootprintTerms t;
  if (!m.terms(fp, &t, window_sigmas)) return RuntimeStatus::kInvalidArgument;
  // A row by its weight, then a flake of it by its own; each uniform rescaled within the chosen
  // interval. Rounding that leaves the target past the end takes the last row with weight.
  double target = u1 * mass / t.wnorm, row_weight = 0.0;
  int64_t fy = 0, x0 = 0, x1 = -1;
  bool found = false;
  double buffer[kPrefixFlakes + 1];
  const double* prefix = m.columnPrefix(t, buffer) ? buffer : nullptr;
  if (cut) {
    // A tile by its weight (windowedMass's products, in its order), then a row of it by the
    // weights along y: the rows of a tile share its sum along x.
    t.cut = cut;
    double row[kPrefixFlakes + 1];
    if (!prefix || !m.axisPrefix(t, false, row)) return RuntimeStatus::kInvalidArgument;
    WindowTile picked{};
    bool any = false;
    m.forEachWindowTile(t, [&](const WindowTile& w) {
      if (found) return;
      const double tw = FlakeNdf::Impl::tileWeight(t, w, prefix, row);
      if (!(tw > 0.0)) return;
      picked = w;
      any = true;
      if (target < tw)
        found = true;
      else
        target -= tw;
    });
    if (!any) return RuntimeStatus::kInvalidArgument;
    x0 = picked.ox + picked.fx0;
    x1 = picked.ox + picked.fx1;
    const double across = prefix[x1 + 1 - t.x0] - prefix[x0 - t.x0];
    if (!found) target = FlakeNdf::Impl::tileWeight(t, picked, prefix, row);
    found = false;
    for (int64_t y = picked.oy + picked.fy0; y <= picked.oy + picked.fy1; ++y) {
      const double w = (row[y + 1 - t.y0] - row[y - t.y0]) * across;
      if (!(w > 0.0)) continue;
      fy = y, row_weight = w;
      if (target < w) {
        found = true;
        break;
      }
      target -= w;
    }
    if (!(row_weight > 0.0)) return RuntimeStatus::kInvalidArgument;
  } else {
    m.forEachDiskRow(t, [&](int64_t y, double gy, int64_t a, int64_t b) {
      const double w = gy * m.rowSum(t, prefix, a, b);
      if (!(w > 0.0)) return true;
      fy = y, x0 = a, x1 = b, row_weight = w;
      if (target < w) {
        found = true;
        return false;
      }
      target -= w;
      return true;
    });
  }
  if (x1 < x0) return RuntimeStatus::kInvalidArgument;
  if (!found) target = row_weight;
  *v1 = std::clamp(target / row_weight, 0.0, 0.99999999999999989);
  int64_t fx = x0;
  if (prefix) {
    // The first flake of the row whose running sum passes the target, by bisection.
    const double before = prefix[x0 - t.x0], chord = prefix[x1 + 1 - t.x0] - before;
    const double goal = before + u2 * chord;
    const double* end = std::upper_bound(prefix + (x0 - t.x0) + 1, prefix + (x1 - t.x0) + 1, goal);
    fx = std::min<int64_t>(x1, t.x0 + (end - prefix) - 1);
    const double lo = prefix[fx - t.x0], g = prefix[fx + 1 - t.x0] - lo;
    *v2 = g > 0.0 ? std::clamp((goal - lo) / g, 0.0, 0.99999999999999989) : 0.5;
  } else {
    double rest = u2 * m.rowSum(t, nullptr, x0, x1), g = 0.0;
    m.forEachWeightIn(t.ux, x0, x1, t.inv2v, [&](int64_t x, double w) {
      fx = x;
      g = w;
      if (rest < w || x == x1) return false;
      rest -= w;
      return true;
    });
    *v2 = g > 0.0 ? std::clamp(rest / g, 0.0, 0.99999999999999989) : 0.5;
  }
  const int64_t gx = ((fx % m.fine_w) + m.fine_w) % m.fine_w, gy = ((fy % m.fine_h) + m.fine_h) % m.fine_h;
  const uint32_t where = m.slot.data[size_t(gy) * size_t(m.fine_w) + size_t(gx)];
  m.lobeOf(m.blocks.data[where / kLeafFlakes], int(where % kLeafFlakes), t.ux - m.flakePosition(fx),
           t.uy - m.flakePosition(fy), t, lobe);
  return RuntimeStatus::kOk;
}

void usePortableFlakeKernels(bool portable) { flakes::portableKernelsOnly().store(portable); }

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

RuntimeStatus FlakeNdf::eval(const Footprint& footprint, const SPoint& s, double* value) const {
  return flakes::pointEval<FootprintTerms>(impl_.get(), footprint, s, value);
}

RuntimeStatus FlakeNdf::mass(const Footprint& footprint, double* value) const {
  return flakes::pointMass<FootprintTerms>(impl_.get(), footprint, value);
}

RuntimeStatus FlakeNdf::pdf(const Footprint& footprint, const SPoint& s, double* value) const {
  return flakes::pointPdf<FootprintTerms>(impl_.get(), footprint, s, value);
}

RuntimeStatus FlakeNdf::average(const Footprint& footprint, const SRect& rect, double* value) const {
  return FlakeNdfAccess::windowedAverage(*this, footprint, rect, kWindowSigmas, value);
}

RuntimeStatus FlakeNdfAccess::windowedAverage(const FlakeNdf& f, const Footprint& footprint, const SRect& rect,
                                              double window_sigmas, double* value) {
  if (!f.impl_ || !value || !validFootprint(footprint) || !validRect(rect) ||
      !(window_sigmas > 0.0 && window_sigmas <= kWindowSigmas))
    return RuntimeStatus::kInvalidArgument;
  const FlakeNdf::Impl& m = *f.impl_;
  FootprintTerms t;
  if (!m.terms(footprint, &t, window_sigmas)) return RuntimeStatus::kInvalidArgument;
  const double x0 = std::max(rect.x0, -1.0), x1 = std::min(rect.x1, 1.0);
  const double y0 = std::max(rect.y0, -1.0), y1 = std::min(rect.y1, 1.0);
  double integral = 0.0;
  if (x1 > x0 && y1 > y0) {
    // A tile or leaf is visited when its lobes may put mass in the rectangle (within 8.5
    // standard deviations of the normal box widened by the mean shift).
    auto overlaps = [&](double lo_x, double lo_y, double hi_x, double hi_y, double jmax, double dmax) {
      const double shift = jmax * t.a * dmax;
      const double sd = std::sqrt(m.sigma_r2 + t.b * jmax * jmax) * 8.5;
      return hi_x + shift + sd > x0 && lo_x - shift - sd < x1 && hi_y + shift + sd > y0 && lo_y - shift - sd < y1;
    };
    auto tile = [&](const TileBound& b, double dmax2) {
      return overlaps(b.lo[0], b.lo[1], b.hi[0], b.hi[1], b.jmax, std::sqrt(dmax2));
    };
    auto leaves = [&](const LeafBounds& lb, const TileBound& tb, double base_x, double base_y) {
      uint32_t mask = 0;
      for (uint32_t i = 0; i < tb.leaves; ++i) {
        const double dx = std::max(std::fabs(base_x - lb.plo_x[i]), std::fabs(base_x - lb.phi_x[i]));
        const double dy = std::max(std::fabs(base_y - lb.plo_y[i]), std::fabs(base_y - lb.phi_y[i]));
        if (overlaps(lb.lo_x[i], lb.lo_y[i], lb.hi_x[i], lb.hi_y[i], lb.jmax[i], std::sqrt(dx * dx + dy * dy)))
          mask |= 1u << i;
      }
      return mask;
    };
    m.forEachLeaf(t, tile, leaves, [&](const LeafVisit& leaf) {
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
  return FlakeNdfAccess::windowedAddImage(*this, footprint, kWindowSigmas, weight, out, out_count);
}

RuntimeStatus FlakeNdfAccess::windowedAddImage(const FlakeNdf& f, const Footprint& footprint, double window_sigmas,
                                               double weight, float* out, size_t out_count) {
  if (!f.impl_ || !(window_sigmas > 0.0 && window_sigmas <= kWindowSigmas)) return RuntimeStatus::kInvalidArgument;
  const FlakeNdf::Impl& m = *f.impl_;
  const int res = m.res;
  const size_t n = size_t(res) * size_t(res);
  if (!out || out_count < n || !validFootprint(footprint) || !std::isfinite(weight))
    return RuntimeStatus::kInvalidArgument;
  FootprintTerms t;
  if (!m.terms(footprint, &t, window_sigmas)) return RuntimeStatus::kInvalidArgument;
  const double bin = 2.0 / res;
  // Each lobe adds its probability over the bins, scaled to a density (divided by the bin area),
  // in the fixed order of the traversal.
  const double to_density = weight * t.wnorm / (bin * bin);
  auto tile = [](const TileBound&, double) { return true; };
  auto leaves = [](const LeafBounds&, const TileBound& tb, double, double) { return leafMask(tb.leaves); };
  m.forEachLeaf(t, tile, leaves, [&](const LeafVisit& leaf) {
    m.forEachFlakeOf(leaf, t, [&](const Block& k, int i, double dx, double dy, double spatial) {
      flakes::Lobe g;
      m.lobeOf(k, i, dx, dy, t, &g);
      flakes::splatLobe(g, to_density * std::exp(-spatial), res, out);
    });
  });
  return RuntimeStatus::kOk;
}

RuntimeStatus FlakeNdf::sample(const Footprint& footprint, double u1, double u2, NdfSample* out) const {
  return FlakeNdfAccess::sample(*this, footprint, u1, u2, out, true);
}

RuntimeStatus FlakeNdfAccess::sample(const FlakeNdf& ndf, const Footprint& footprint, double u1, double u2,
                                     NdfSample* out, bool with_pdf) {
  if (!ndf.impl_ || !out || !validFootprint(footprint) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  const FlakeNdf::Impl& m = *ndf.impl_;
  FootprintTerms t;
  if (!m.terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  const double sum_x = m.weightSum(t, true), sum_y = m.weightSum(t, false);
  const double total = t.wnorm * sum_x * sum_y;
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
  // The footprint weights are separable: a row by its weight, then a column; each uniform is
  // rescaled within the chosen interval and reused for the lobe.
  auto pick = [&](bool along_x, double u, double sum, double* rest) {
    double target = u * sum, g = 0.0;
    int64_t f = along_x ? t.x0 : t.y0;
    const int64_t last = along_x ? t.x1 : t.y1;
    m.forEachWeight(t, along_x, [&](int64_t index, double weight) {
      f = index;
      g = weight;
      if (target < weight || index == last) return false;
      target -= weight;
      return true;
    });
    *rest = g > 0.0 ? std::clamp(target / g, 0.0, 0.99999999999999989) : 0.5;
    return f;
  };
  double v1, v2;
  const int64_t fy = pick(false, u1, sum_y, &v1);
  const int64_t fx = pick(true, u2, sum_x, &v2);
  const int64_t gx = ((fx % m.fine_w) + m.fine_w) % m.fine_w, gy = ((fy % m.fine_h) + m.fine_h) % m.fine_h;
  const uint32_t where = m.slot.data[size_t(gy) * size_t(m.fine_w) + size_t(gx)];
  flakes::Lobe g;
  m.lobeOf(m.blocks.data[where / kLeafFlakes], int(where % kLeafFlakes), t.ux - m.flakePosition(fx),
           t.uy - m.flakePosition(fy), t, &g);
  flakes::lobePoint(g, v1, v2, &out->s.x, &out->s.y);
  out->pdf = with_pdf && inSquare(out->s) ? m.evalAt(t, out->s.x, out->s.y) / total : 0.0;
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
