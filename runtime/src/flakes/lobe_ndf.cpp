// SPDX-License-Identifier: Apache-2.0
// Clustered position-normal lobes for mid-size footprints (see lobe_ndf.h).
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/lobe_ndf.h>

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
#include <limits>
#include <mutex>
#include <new>

namespace glintbake::runtime {
namespace {

// The reduction's merge costs: inlined into their loop (which the compiler then vectorises) and
// into the AVX2 copy of that loop (which would otherwise call the SSE2 code).
#if defined(__GNUC__)
#define GLINTBAKE_LOBE_INLINE inline __attribute__((always_inline))
#else
#define GLINTBAKE_LOBE_INLINE inline
#endif

constexpr int kLanes = kMaxLobesPerTile;
constexpr int kFinestTile = 4;  // flakes per side of a level-0 tile
static_assert(2 * kFinestTile == flakes::kTileFlakes, "level 1's tiles are the exact flakes' tiles");
// Where the footprint weight is low the clustered levels take coarser tiles: a tile k levels above
// the footprint's own is taken where its nearest point lies at least sqrt(2 k kCoarsenStep)
// standard deviations from the centre (1.4, 2 and 2.4 for k = 1..kMaxCoarser), that is where the
// weight has fallen below e^-k of its peak.
constexpr double kCoarsenStep = 1.0;
constexpr int kMaxCoarser = 3;
// Spatial truncation, in standard deviations of a lobe's footprint weight: the lobes beyond hold
// about 1% of the mass (a disk of 3 standard deviations); eval, mass and sample truncate alike.
constexpr double kWindowSigmas = 3.0;
constexpr double kMaxSpatial = kWindowSigmas * kWindowSigmas / 2;
// The footprint weights are scaled by the inverse of the share of a Gaussian inside the window
// (1 - e^-4.5), so that the NDF of a footprint inside the map integrates to 1 as on every path.
const double kWindowNorm = 1.0 / (1.0 - std::exp(-kMaxSpatial));
constexpr double kMaxExponent = 18.0;  // lobes below e^-18 of their peak at s are left out
constexpr int kMaxWindowTiles = 40;    // tiles per side of a window at most
// Tiles whose masses sample() keeps for its pick (a window's tiles, with a margin for the split
// of a repeating window at the map's edges; more fall back to a second weighing walk).
constexpr int kMaxSampleTiles = (kMaxWindowTiles + 2) * (kMaxWindowTiles + 2);
constexpr int kMaxSide = 1 << 16;
// Levels at most: tiles of 4 << l flakes per side, up to a side of 2^16 texels at rate 16 (2^20
// flakes) at l = 18.
constexpr int kMaxLevels = 20;
constexpr uint64_t kMaxFlakes = uint64_t(1) << 30;
constexpr float kPaddingPosition = 1e15f;  // position of unused lanes: weight 0
// Items grouped into one tile at most: the flakes of a level-0 tile, or the lobes of four children.
constexpr int kMaxItems = std::max(kFinestTile * kFinestTile, 4 * kLanes);

// A 4D Gaussian in (position u, normal s) while the hierarchy is built: weight, means, and the
// covariance blocks uu {xx, xy, yy}, su {s_x u_x, s_x u_y, s_y u_x, s_y u_y}, ss {xx, xy, yy}.
struct Gauss4 {
  double w;
  double c[2], m[2];
  double uu[3], su[4], ss[3];
};

// The lobes of one tile, one lane each (structure of arrays for the four-lane loop). Positions
// are relative to the tile's origin, in texels.
struct Block {
  float w[kLanes], cx[kLanes], cy[kLanes], mx[kLanes], my[kLanes];
  float uxx[kLanes], uxy[kLanes], uyy[kLanes];
  float s00[kLanes], s01[kLanes], s10[kLanes], s11[kLanes];
  float sxx[kLanes], sxy[kLanes], syy[kLanes];
};

// What the cut reads of a tile before its block: the largest trace of S_uu over its lobes (which
// bounds their smallest spatial exponent) and the number of lobes. There are no bounds in s: the
// kernel's first pass rejects the lobes that cannot reach s for less than a test of the tile's
// box of means did (evalAt).
struct Bound {
  float uu;
  uint32_t count;
};

struct Level {
  int tile = 0;  // flakes per side
  int tiles_x = 0, tiles_y = 0;
  size_t first = 0;  // index of its first block
};

// The moments of the mixture of items[idx[0..n)] (n >= 1).
Gauss4 momentMatch(const Gauss4* items, const int* idx, int n) {
  Gauss4 g{};
  for (int a = 0; a < n; ++a) {
    const Gauss4& x = items[idx[a]];
    g.w += x.w;
    for (int d = 0; d < 2; ++d) {
      g.c[d] += x.w * x.c[d];
      g.m[d] += x.w * x.m[d];
    }
  }
  const double inv = 1.0 / g.w;
  for (int d = 0; d < 2; ++d) {
    g.c[d] *= inv;
    g.m[d] *= inv;
  }
  for (int a = 0; a < n; ++a) {
    const Gauss4& x = items[idx[a]];
    const double dc[2] = {x.c[0] - g.c[0], x.c[1] - g.c[1]}, dm[2] = {x.m[0] - g.m[0], x.m[1] - g.m[1]};
    const double f = x.w * inv;
    g.uu[0] += f * (x.uu[0] + dc[0] * dc[0]);
    g.uu[1] += f * (x.uu[1] + dc[0] * dc[1]);
    g.uu[2] += f * (x.uu[2] + dc[1] * dc[1]);
    g.su[0] += f * (x.su[0] + dm[0] * dc[0]);
    g.su[1] += f * (x.su[1] + dm[0] * dc[1]);
    g.su[2] += f * (x.su[2] + dm[1] * dc[0]);
    g.su[3] += f * (x.su[3] + dm[1] * dc[1]);
    g.ss[0] += f * (x.ss[0] + dm[0] * dm[0]);
    g.ss[1] += f * (x.ss[1] + dm[0] * dm[1]);
    g.ss[2] += f * (x.ss[2] + dm[1] * dm[1]);
  }
  return g;
}

// ln(|x| + 1e-300) (ln x for x > 1e-284, finite for every finite x), to about 1e-11 relative: the
// exponent from the bits, then the atanh series of the mantissa m in [1, 2) (t = (m - 1) / (m + 1)
// <= 1/3, eleven terms). Branch-free double arithmetic, so that the compiler vectorises the loops
// that call it and every machine gets the same bits.
GLINTBAKE_LOBE_INLINE double logPositive(double x) {
  x = std::fabs(x) + 1e-300;  // without a comparison, which would keep the loops scalar
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  // The biased exponent as a double (2^52 + e, less 2^52), and the mantissa.
  const uint64_t eb = (bits >> 52) | 0x4330000000000000ULL;
  const uint64_t mb = (bits & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL;
  double e, m;
  std::memcpy(&e, &eb, sizeof e);
  std::memcpy(&m, &mb, sizeof m);
  e -= 4503599627370496.0 + 1023.0;
  const double t = (m - 1.0) / (m + 1.0), t2 = t * t;
  double series = 1.0 / 19 + t2 * (1.0 / 21);
  series = 1.0 / 17 + t2 * series;
  series = 1.0 / 15 + t2 * series;
  series = 1.0 / 13 + t2 * series;
  series = 1.0 / 11 + t2 * series;
  series = 1.0 / 9 + t2 * series;
  series = 1.0 / 7 + t2 * series;
  series = 1.0 / 5 + t2 * series;
  series = 1.0 / 3 + t2 * series;
  series = 1.0 + t2 * series;
  return 2.0 * t * series + e * 0.69314718055994530942;
}

// The normal marginals of the items being reduced, one array per term (so that a row of merge
// costs is one vectorised loop): weight, mean, S_ss {xx, xy, yy} and ln det S_ss.
struct Marginals {
  double w[kMaxItems], m0[kMaxItems], m1[kMaxItems];
  double sxx[kMaxItems], sxy[kMaxItems], syy[kMaxItems], ld[kMaxItems];
  void set(int i, const Gauss4& g) {
    w[i] = g.w;
    m0[i] = g.m[0];
    m1[i] = g.m[1];
    sxx[i] = g.ss[0];
    sxy[i] = g.ss[1];
    syy[i] = g.ss[2];
    ld[i] = logPositive(g.ss[0] * g.ss[2] - g.ss[1] * g.ss[1]);
  }
};

// costRow: row i of the merge costs against items [from, count). The cost of replacing lobes x
// and y by their moment-matched union, on their normal marginals,
//   B = 1/2 [(w_x + w_y) ln det S_xy - w_x ln det S_x - w_y ln det S_y],
// an upper bound on the Kullback-Leibler divergence the merge adds to the mixture (Runnalls 2007,
// "Kullback-Leibler approach to Gaussian mixture reduction", IEEE Trans. AES 43(3)). Symmetric to
// the bit (every term is), so rows computed for j > i can be mirrored; +inf on the diagonal.
GLINTBAKE_LOBE_INLINE void costRowImpl(const Marginals& p, int i, int from, int count, double* row) {
  const double wi = p.w[i], m0 = p.m0[i], m1 = p.m1[i], sxx = p.sxx[i], sxy = p.sxy[i], syy = p.syy[i];
  const double li = wi * p.ld[i];
  for (int j = from; j < count; ++j) {
    const double wj = p.w[j], w = wi + wj, inv = 1.0 / w;
    const double fi = wi * inv, fj = wj * inv, f = fi * fj;
    const double dx = m0 - p.m0[j], dy = m1 - p.m1[j];
    const double a = fi * sxx + fj * p.sxx[j] + f * (dx * dx);
    const double b = fi * sxy + fj * p.sxy[j] + f * (dx * dy);
    const double c = fi * syy + fj * p.syy[j] + f * (dy * dy);
    row[j] = 0.5 * (w * logPositive(a * c - b * b) - (li + wj * p.ld[j]));
  }
  row[i] = std::numeric_limits<double>::infinity();
}

#if GLINTBAKE_FLAKES_AVX2
GLINTBAKE_FLAKES_AVX2_BEGIN
// The same loop vectorised four doubles wide (AVX2 without fused multiply-add: the same bits).
void costRowAvx2(const Marginals& p, int i, int from, int count, double* row) { costRowImpl(p, i, from, count, row); }
GLINTBAKE_FLAKES_AVX2_END
#endif

void costRow(const Marginals& p, int i, int from, int count, double* row) {
#if GLINTBAKE_FLAKES_AVX2
  if (flakes::hasAvx2()) return costRowAvx2(p, i, from, count, row);
#endif
  costRowImpl(p, i, from, count, row);
}

// Groups items[0..n) (weights > 0) into at most k lobes by greedy pairwise merging: while more
// than k remain, the pair of least merge cost (ties to the lower slot) is replaced by its
// moment-matched union (so every lobe keeps the exact weight, mean and covariance of the items it
// stands for). The cost is taken on the normal marginals because the footprints a level answers
// are at least 1 / (tile ratio) times its tiles: across a tile the footprint weight changes little
// and what the image sees is the mixture of the tile's normal distributions. Every row caches its
// cheapest partner, so a merge costs one new row of costs and a rescan of the rows that pointed at
// the pair. Writes the lobes to out and returns their count.
int clusterLobes(const Gauss4* items, int n, int k, Gauss4* out) {
  if (n <= k) {
    for (int i = 0; i < n; ++i) out[i] = items[i];
    return n;
  }
  // The live items are g[0..count): a merge keeps the union in the lower slot and moves the last
  // item into the upper one, so that every row of costs stays dense.
  Gauss4 g[kMaxItems];
  Marginals p;
  double cost[kMaxItems][kMaxItems];
  int best[kMaxItems];  // the cheapest partner of every item
  for (int i = 0; i < n; ++i) {
    g[i] = items[i];
    p.set(i, g[i]);
  }
  for (int i = 0; i < n; ++i) {
    costRow(p, i, i + 1, n, cost[i]);
    for (int j = i + 1; j < n; ++j) cost[j][i] = cost[i][j];
  }
  int count = n;
  double best_cost[kMaxItems];  // cost[i][best[i]]
  auto rescan = [&](int i) {
    best[i] = int(std::min_element(cost[i], cost[i] + count) - cost[i]);  // the first of equal minima
    best_cost[i] = cost[i][best[i]];
  };
  for (int i = 0; i < n; ++i) rescan(i);
  while (count > k) {
    int bi = 0;
    for (int i = 1; i < count; ++i)
      if (best_cost[i] < best_cost[bi]) bi = i;
    int bj = best[bi];
    if (bj < bi) std::swap(bi, bj);
    const int pair[2] = {bi, bj};
    g[bi] = momentMatch(g, pair, 2);
    p.set(bi, g[bi]);
    // Move the last item into slot bj.
    const int last = --count;
    if (bj != last) {
      g[bj] = g[last];
      p.set(bj, g[bj]);
      best[bj] = best[last];
      best_cost[bj] = best_cost[last];
      for (int j = 0; j <= last; ++j) cost[bj][j] = cost[last][j];
      for (int j = 0; j <= last; ++j) cost[j][bj] = cost[j][last];
      cost[bj][bj] = std::numeric_limits<double>::infinity();
    }
    costRow(p, bi, 0, count, cost[bi]);
    for (int j = 0; j < count; ++j) cost[j][bi] = cost[bi][j];
    rescan(bi);
    // A row keeps its partner unless the union costs less, or unless its partner was one of the
    // pair: then the union if it costs no more than the old best (every other entry of the row is
    // unchanged and no cheaper), else a rescan. A partner in the last slot has moved to bj.
    for (int i = 0; i < count; ++i) {
      if (i == bi) continue;
      const bool merged = best[i] == bi || best[i] == bj;
      if (best[i] == last) best[i] = bj;
      const double c = cost[i][bi];
      if (merged) {
        if (c <= best_cost[i]) {
          best[i] = bi;
          best_cost[i] = c;
        } else {
          rescan(i);
        }
      } else if (c < best_cost[i]) {
        best[i] = bi;
        best_cost[i] = c;
      }
    }
  }
  for (int i = 0; i < count; ++i) out[i] = g[i];
  return count;
}

// The float constants of one point query shared by every lane of the kernel (lobe_kernel.inc).
struct KernelTerms {
  float sp2, sx, sy;
  float spatial_cut;  // kMaxSpatial
  float keep_cut;     // the first pass's cutoff, kMaxExponent plus a margin
};

// Lanes kept by the kernel's first pass, in traversal order (kLaneList of them at most, plus the
// room the branch-free writes and the padding to a whole vector take).
constexpr int kLaneList = 512;
struct LaneList {
  alignas(64) float spatial[kLaneList + 32];
  alignas(64) float num[kLaneList + 32];
  alignas(64) float det_c[kLaneList + 32];
  alignas(64) float det_ac[kLaneList + 32];
  alignas(64) float w[kLaneList + 32];
};

namespace sse {
using V = flakes::F4;
#include "lobe_kernel.inc"
}  // namespace sse

#if GLINTBAKE_FLAKES_AVX2
GLINTBAKE_FLAKES_AVX2_BEGIN
namespace avx2 {
using V = flakes::F8;
#include "lobe_kernel.inc"
}  // namespace avx2
GLINTBAKE_FLAKES_AVX2_END
#else
namespace avx2 = sse;  // no AVX2 copy: both names are the SSE2 kernels
#endif

// The kernels of the processor: AVX2 where it has it (the same bits), else SSE2 or scalar.
int keepLanes(bool wide, const Block& b, int count, const KernelTerms& c, float bx, float by, LaneList* list, int n) {
  return wide ? avx2::keepLanes(b, count, c, bx, by, list, n) : sse::keepLanes(b, count, c, bx, by, list, n);
}
void laneValues(bool wide, LaneList* list, int n, float cutoff) {
  if (wide)
    avx2::laneValues(list, n, cutoff);
  else
    sse::laneValues(list, n, cutoff);
}

void laneWeightKernel(bool wide, const Block& b, int count, float sp2, float bx, float by, float scale, float cut,
                      float* lanes) {
  if (wide)
    avx2::laneWeights(b, count, sp2, bx, by, scale, cut, lanes);
  else
    sse::laneWeights(b, count, sp2, bx, by, scale, cut, lanes);
}

// The footprint terms of one query: centre (reduced into the map for repeating maps), sigma_p^2,
// the answering level and the window.
struct Terms {
  Footprint fp;  // as queried (the exact flakes reduce its centre as the lobes do)
  double sigma, ux, uy, sp2;
  int finest, coarsest;  // the answering level (levelFor) and the coarsest the cut may take tiles from
  bool exact_mode;       // answered by the exact flakes' window (level 0 with every flake a lobe)
  // Level 0 with every flake a lobe under a cut: the level-1 tiles the cut would split into
  // level-0 tiles (inner_cut) are answered by the exact flakes' evaluator, which prunes them by
  // normal, the coarser tiles farther out by their lobes. skip_inner leaves the inner tiles out of
  // the lobes' traversal (eval, mass, sample); average and image walk them as level-0 lobes.
  bool inner_exact, skip_inner;
  flakes::TileCut inner_cut;
  double tile_texels;  // tile side of the finest level
  double reach;
};

}  // namespace

struct LobeNdf::Impl {
  int width = 0, height = 0, rate = 1, fine_w = 0, fine_h = 0;
  bool repeat = true;
  double step = 1.0, sigma_h2 = 0.0, sigma_r2 = 0.0;
  int res = 128, lobes = kLanes;
  double tile_ratio = kDefaultLobeTileRatio;  // a footprint is answered on tiles of at most this x its std
  Level levels[kMaxLevels];
  int level_count = 0;
  // Level 0 is built by build() (unless made on demand, below); a level above on its first query
  // (or by prepare()), once, from the level below: std::call_once orders its writes before every
  // reader of that level.
  mutable std::once_flag level_built[kMaxLevels];
  // Blocks and bounds of the stored levels. With every flake its own lobe on level 0 (lobes ==
  // kLanes) that level is not stored: its tiles are made from the normals when level 1 is grouped
  // and when an image or average walks them (level0Tile), the same bits as stored ones, and the
  // normals (8 bytes a texel) are kept instead of its blocks (60 bytes a flake).
  bool virtual_level0 = false;
  Array<float> normals;  // the source's (n_x, n_y) per texel, kept when level 0 is virtual
  Array<Block> blocks;
  Array<Bound> bounds;
  // With every flake its own lobe on level 0 (lobes == kLanes), that level's eval is the exact
  // flakes' with the lobes' window: answered by their evaluator, which prunes by normal. exact is
  // own_exact, or the FlakeNdf of the same source that an asset's hand-over shares (build's shared).
  FlakeNdf own_exact;
  const FlakeNdf* exact = nullptr;

  RuntimeStatus build(const TexelSource& src, int rate_in, double sigma_r, int lobes_in, int res_in,
                      const FlakeNdf* shared);
  // One tile's lobes as a block (lanes past count: weight 0, far away) and its bound.
  static void packTile(const Gauss4* lobes_of_tile, int count, Block* b, Bound* d);
  void storeTile(size_t index, const Gauss4* lobes_of_tile, int count);
  // The flakes of level-0 tile (tx, ty) as 4D Gaussians (positions relative to its origin): count.
  int level0Items(int tx, int ty, Gauss4* items) const;
  // Level-0 tile (tx, ty) made from the normals, as build() would store it (virtual_level0 only).
  void level0Tile(int tx, int ty, Block* b, Bound* d) const;
  // The block and bound of tile (tx, ty) of level li: stored, or made into *scratch.
  const Block& tileBlock(int li, int tx, int ty, Block* scratch, Bound* scratch_bound, const Bound** bound) const;
  // Levels 1..li built (thread-safe); returns levels[li].
  const Level& levelBuilt(int li) const;
  void buildLevel(int li);
  void gatherChildren(int child, int tx, int ty, Gauss4* out, int* count) const;
  int levelFor(double sigma) const;
  // The levels of a footprint of this sigma and how level 0 is answered (Terms' finest, coarsest,
  // exact_mode, inner_exact, skip_inner, inner_cut).
  void chooseLevels(double sigma, Terms* t) const;
  // Squared distance from the footprint centre beyond which the cut takes a tile of level li.
  static double cutLimit(const Terms& t, int li) { return 2.0 * kCoarsenStep * double(li - t.finest) * t.sp2; }
  bool terms(const Footprint& fp, Terms* t) const;
  // Calls visit(block, bound, base_x, base_y) for every tile of the footprint's
  // cut within the spatial truncation (tiles of the answering level near the centre, of up to
  // kMaxCoarser levels above it farther out; the same tiles in the same order for every query of
  // a footprint), base = u_Q - the origin of the tile's periodic image.
  template <typename Visit>
  void forEachTile(const Terms& t, Visit&& visit) const;
  template <typename Accept>
  void visitNode(const Terms& t, int li, int tx, int ty, double ux, double uy, Accept& accept) const;
  // Calls visit(lobe, weight) for every lane of the block within the spatial truncation, with the
  // footprint-conditioned s-plane lobe and its footprint weight.
  template <typename Visit>
  void forEachLobe(const Block& b, const Bound& bound, double bx, double by, double sp2, Visit&& visit) const;
  // The footprint-conditioned s-plane lobe of lane i and its footprint weight (scalar, double).
  double lobeAt(const Block& b, int i, double bx, double by, double sp2, flakes::Lobe* g) const;
  // The footprint weights of a block's lanes, four at a time (0 beyond the spatial truncation),
  // written to lanes[kLanes]; returns their sum. mass and sample share it, so that sampling picks a
  // lobe with exactly the probability its weight has in the mass.
  double laneWeights(const Block& b, const Bound& bound, double bx, double by, double sp2, float* lanes) const;
  double evalAt(const Terms& t, double sx, double sy) const;
  double massOf(const Terms& t) const;
  // The exact flakes' share of an inner_exact footprint: eval at s and mass.
  double innerEval(const Terms& t, double sx, double sy) const;
  double innerMass(const Terms& t) const;
};

RuntimeStatus LobeNdf::Impl::build(const TexelSource& src, int rate_in, double sigma_r, int lobes_in, int res_in,
                                   const FlakeNdf* shared) {
  width = src.width();
  height = src.height();
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide) return RuntimeStatus::kInvalidArgument;
  if (rate_in < 1 || rate_in > 16 || !(sigma_r > 0.0 && sigma_r <= 1.0) || lobes_in < 1 || lobes_in > kLanes ||
      res_in < 2 || res_in > 4096)
    return RuntimeStatus::kInvalidArgument;
  if (uint64_t(width) * uint64_t(height) * uint64_t(rate_in) * uint64_t(rate_in) > kMaxFlakes)
    return RuntimeStatus::kInvalidArgument;
  rate = rate_in;
  repeat = src.repeats();
  res = res_in;
  lobes = lobes_in;
  sigma_r2 = sigma_r * sigma_r;
  step = 1.0 / rate;
  const double sigma_h = step * 1.5 / std::sqrt(12.0);
  sigma_h2 = sigma_h * sigma_h;
  fine_w = width * rate;
  fine_h = height * rate;

  virtual_level0 = lobes == kLanes;
  size_t total = 0;
  for (int tile = kFinestTile;; tile *= 2) {
    Level& l = levels[level_count++];
    l.tile = tile;
    l.tiles_x = (fine_w + tile - 1) / tile;
    l.tiles_y = (fine_h + tile - 1) / tile;
    l.first = total;
    if (level_count > 1 || !virtual_level0) total += size_t(l.tiles_x) * size_t(l.tiles_y);
    if (l.tiles_x == 1 && l.tiles_y == 1) break;
  }
  if (!normals.allocate(size_t(width) * size_t(height) * 2) || !blocks.allocate(total) || !bounds.allocate(total))
    return RuntimeStatus::kOutOfMemory;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float* n = normals.data + (size_t(y) * size_t(width) + size_t(x)) * 2;
      src.normal(x, y, n);
      if (!std::isfinite(n[0]) || !std::isfinite(n[1])) return RuntimeStatus::kInvalidArgument;
    }
  }
  // Level 0: the flakes of every tile as 4D Gaussians, grouped (stored unless virtual).
  const Level& l0 = levels[0];
  if (!virtual_level0) {
    Gauss4 items[kMaxItems], grouped[kLanes];
    for (int ty = 0; ty < l0.tiles_y; ++ty) {
      for (int tx = 0; tx < l0.tiles_x; ++tx) {
        const int n = level0Items(tx, ty, items);
        storeTile(l0.first + size_t(ty) * size_t(l0.tiles_x) + size_t(tx), grouped,
                  clusterLobes(items, n, lobes, grouped));
      }
    }
  }
  if (lobes == kLanes) {
    if (shared) {
      exact = shared;
    } else {
      InterleavedTexels texels(width, height, repeat, normals.data, 2);
      if (RuntimeStatus st = own_exact.build(texels, rate, sigma_r, res); st != RuntimeStatus::kOk) return st;
      exact = &own_exact;
    }
  }
  if (!virtual_level0) normals.release();
  return RuntimeStatus::kOk;
}

int LobeNdf::Impl::level0Items(int tx, int ty, Gauss4* items) const {
  const double area = step * step;
  int n = 0;
  for (int fy = ty * kFinestTile; fy < std::min(fine_h, (ty + 1) * kFinestTile); ++fy) {
    for (int fx = tx * kFinestTile; fx < std::min(fine_w, (tx + 1) * kFinestTile); ++fx) {
      float nk[2], jk[4];
      flakes::flakeAt(normals.data, width, height, repeat, (fx + 0.5) * step, (fy + 0.5) * step, nk, jk);
      Gauss4& g = items[n++];
      g.w = area;
      g.c[0] = (fx - tx * kFinestTile + 0.5) * step;
      g.c[1] = (fy - ty * kFinestTile + 0.5) * step;
      g.m[0] = nk[0];
      g.m[1] = nk[1];
      g.uu[0] = sigma_h2;
      g.uu[1] = 0.0;
      g.uu[2] = sigma_h2;
      for (int a = 0; a < 4; ++a) g.su[a] = sigma_h2 * double(jk[a]);
      g.ss[0] = sigma_r2 + sigma_h2 * (double(jk[0]) * jk[0] + double(jk[1]) * jk[1]);
      g.ss[1] = sigma_h2 * (double(jk[0]) * jk[2] + double(jk[1]) * jk[3]);
      g.ss[2] = sigma_r2 + sigma_h2 * (double(jk[2]) * jk[2] + double(jk[3]) * jk[3]);
    }
  }
  return n;
}

void LobeNdf::Impl::level0Tile(int tx, int ty, Block* b, Bound* d) const {
  // A level-0 tile holds at most kFinestTile^2 = kLanes flakes: as many lobes as a tile keeps when
  // it is made (clusterLobes would return them unchanged).
  static_assert(kFinestTile * kFinestTile == kLanes, "a made tile keeps every flake");
  Gauss4 items[kLanes];
  const int n = level0Items(tx, ty, items);
  packTile(items, n, b, d);
}

const Block& LobeNdf::Impl::tileBlock(int li, int tx, int ty, Block* scratch, Bound* scratch_bound,
                                      const Bound** bound) const {
  if (li == 0 && virtual_level0) {
    level0Tile(tx, ty, scratch, scratch_bound);
    *bound = scratch_bound;
    return *scratch;
  }
  const size_t index = levels[li].first + size_t(ty) * size_t(levels[li].tiles_x) + size_t(tx);
  *bound = &bounds.data[index];
  return blocks.data[index];
}

// A level above 0: the lobes of the four children of every tile, grouped again. Most of the
// build's time is here (level 1 about three quarters of it), so it waits for a query that needs it.
void LobeNdf::Impl::buildLevel(int li) {
  Gauss4 items[kMaxItems], grouped[kLanes];
  const Level& l = levels[li];
  for (int ty = 0; ty < l.tiles_y; ++ty) {
    for (int tx = 0; tx < l.tiles_x; ++tx) {
      int n = 0;
      gatherChildren(li - 1, tx, ty, items, &n);
      storeTile(l.first + size_t(ty) * size_t(l.tiles_x) + size_t(tx), grouped, clusterLobes(items, n, lobes, grouped));
    }
  }
}

const Level& LobeNdf::Impl::levelBuilt(int li) const {
  if (li > 0) {
    std::call_once(level_built[li], [this, li] {
      levelBuilt(li - 1);
      // The only writer of this level's blocks, before any reader of them (call_once).
      const_cast<Impl*>(this)->buildLevel(li);
    });
  }
  return levels[li];
}

// The lobes of the (up to four) children of tile (tx, ty) of the level above `child`, positions
// relative to the parent's origin.
void LobeNdf::Impl::gatherChildren(int child_level, int tx, int ty, Gauss4* out, int* count) const {
  int n = 0;
  const Level& child = levels[child_level];
  const double side = child.tile * step;
  Block scratch;
  Bound scratch_bound;
  for (int cy = 2 * ty; cy < std::min(child.tiles_y, 2 * ty + 2); ++cy) {
    for (int cx = 2 * tx; cx < std::min(child.tiles_x, 2 * tx + 2); ++cx) {
      const Bound* bound = nullptr;
      const Block& b = tileBlock(child_level, cx, cy, &scratch, &scratch_bound, &bound);
      const double ox = (cx - 2 * tx) * side, oy = (cy - 2 * ty) * side;
      for (uint32_t i = 0; i < bound->count; ++i) {
        Gauss4& g = out[n++];
        g.w = b.w[i];
        g.c[0] = ox + b.cx[i];
        g.c[1] = oy + b.cy[i];
        g.m[0] = b.mx[i];
        g.m[1] = b.my[i];
        g.uu[0] = b.uxx[i];
        g.uu[1] = b.uxy[i];
        g.uu[2] = b.uyy[i];
        g.su[0] = b.s00[i];
        g.su[1] = b.s01[i];
        g.su[2] = b.s10[i];
        g.su[3] = b.s11[i];
        g.ss[0] = b.sxx[i];
        g.ss[1] = b.sxy[i];
        g.ss[2] = b.syy[i];
      }
    }
  }
  *count = n;
}

void LobeNdf::Impl::storeTile(size_t index, const Gauss4* g, int count) {
  packTile(g, count, &blocks.data[index], &bounds.data[index]);
}

void LobeNdf::Impl::packTile(const Gauss4* g, int count, Block* block, Bound* bound) {
  Block& b = *block;
  Bound& d = *bound;
  d.uu = 0.0f;
  d.count = uint32_t(count);
  for (int i = 0; i < kLanes; ++i) {
    const bool used = i < count;
    const Gauss4 x = used ? g[i] : Gauss4{0.0, {0, 0}, {0, 0}, {1, 0, 1}, {0, 0, 0, 0}, {1, 0, 1}};
    b.w[i] = float(x.w);
    b.cx[i] = used ? float(x.c[0]) : kPaddingPosition;
    b.cy[i] = used ? float(x.c[1]) : kPaddingPosition;
    b.mx[i] = float(x.m[0]);
    b.my[i] = float(x.m[1]);
    b.uxx[i] = float(x.uu[0]);
    b.uxy[i] = float(x.uu[1]);
    b.uyy[i] = float(x.uu[2]);
    b.s00[i] = float(x.su[0]);
    b.s01[i] = float(x.su[1]);
    b.s10[i] = float(x.su[2]);
    b.s11[i] = float(x.su[3]);
    b.sxx[i] = float(x.ss[0]);
    b.sxy[i] = float(x.ss[1]);
    b.syy[i] = float(x.ss[2]);
    if (!used) continue;
    d.uu = std::max(d.uu, float((x.uu[0] + x.uu[2]) * (1.0 + 1e-6)));
  }
}

int LobeNdf::Impl::levelFor(double sigma) const {
  const double want = tile_ratio * sigma * rate;
  int l = 0;
  while (l + 1 < level_count && double(levels[l + 1].tile) <= want) ++l;
  return l;
}

void LobeNdf::Impl::chooseLevels(double sigma, Terms* t) const {
  t->sigma = sigma;
  t->sp2 = sigma * sigma;
  t->finest = levelFor(sigma);
  // Coarser levels up to kMaxCoarser above the answering one, when its tiles are within
  // tile_ratio sigma (not when the finest level is answering a footprint narrower than that).
  t->coarsest = t->finest;
  if (double(levels[t->finest].tile) <= tile_ratio * sigma * rate)
    t->coarsest = std::min(level_count - 1, t->finest + kMaxCoarser);
  t->exact_mode = t->inner_exact = t->skip_inner = false;
  t->inner_cut = {0.0, 0.0};
  if (t->finest != 0 || !exact) return;
  // The exact flakes answer the inner tiles when every flake of them lies well inside the
  // window's disk (their mass is then the product of sums along the axes) and the window fits
  // the flakes' running sums; else, and without a cut, the whole window.
  const double side = levels[std::min(1, level_count - 1)].tile * step;
  const double limit2 = cutLimit(*t, 1);
  const double far = std::sqrt(limit2) + side * std::sqrt(2.0);
  const double v = t->sp2 + sigma_h2;
  if (t->coarsest > 0 && far * far < 0.98 * 2.0 * kMaxSpatial * v &&
      2.0 * kWindowSigmas * std::sqrt(v) * rate + 4.0 < double(FlakeNdfAccess::kPrefixFlakes)) {
    t->inner_exact = t->skip_inner = true;
    t->inner_cut = {side, limit2};
  } else {
    t->exact_mode = true;
    t->coarsest = 0;
  }
}

bool LobeNdf::Impl::terms(const Footprint& fp, Terms* t) const {
  t->fp = fp;
  chooseLevels(fp.sigma, t);
  levelBuilt(t->coarsest);
  t->tile_texels = levels[t->finest].tile * step;
  t->ux = fp.x;
  t->uy = fp.y;
  if (repeat) {
    t->ux -= format::NdfBlendAxis::floorOf(t->ux / width) * width;
    t->uy -= format::NdfBlendAxis::floorOf(t->uy / height) * height;
  } else if (!(std::fabs(t->ux) < 1e15 && std::fabs(t->uy) < 1e15)) {
    return false;
  }
  t->reach = kWindowSigmas * std::sqrt(t->sp2 + sigma_h2) + t->tile_texels;
  return 2.0 * t->reach / (levels[t->coarsest].tile * step) + 2.0 <= double(kMaxWindowTiles);
}

template <typename Visit>
void LobeNdf::Impl::forEachTile(const Terms& t, Visit&& visit) const {
  // The tiles of the cut are gathered in batches from their geometry alone; then the bounds of a
  // batch are prefetched and read, and the blocks of the tiles within the spatial truncation
  // (about a kilobyte each) prefetched a few tiles ahead of the one visited, so that their cache
  // misses overlap.
  struct TileRef {
    size_t index;
    double bx, by, d2;
    int tx, ty;
    bool made;  // a tile of the virtual level 0: made from the normals when visited
  };
  constexpr int kBatch = 64, kAhead = 4;
  TileRef batch[kBatch];
  int n = 0;
  auto fetch = [&](const void* p, size_t size) {
    const char* bytes = static_cast<const char*>(p);
    for (size_t o = 0; o < size; o += 64) flakes::prefetch(bytes + o);
    flakes::prefetch(bytes + size - 1);
  };
  // The bound of a level-0 tile as packTile gives it: every flake has S_uu = sigma_h^2 I.
  const Bound made_bound{float((sigma_h2 + sigma_h2) * (1.0 + 1e-6)), 1};
  Block made;
  Bound made_tile_bound;
  auto flush = [&] {
    for (int i = 0; i < n; ++i)
      if (!batch[i].made) fetch(bounds.data + batch[i].index, sizeof(Bound));
    int kept = 0;
    for (int i = 0; i < n; ++i) {
      const TileRef& r = batch[i];
      const Bound& bound = r.made ? made_bound : bounds.data[r.index];
      if (bound.count == 0) continue;
      // Smallest spatial exponent of the tile: A <= (sigma_p^2 + tr S_uu) I.
      const double spatial_min = 0.5 * r.d2 / (t.sp2 + double(bound.uu));
      if (spatial_min > kMaxSpatial) continue;
      if (kept < kAhead && !r.made) fetch(blocks.data + r.index, sizeof(Block));
      batch[kept++] = r;
    }
    for (int i = 0; i < kept; ++i) {
      if (i + kAhead < kept && !batch[i + kAhead].made) fetch(blocks.data + batch[i + kAhead].index, sizeof(Block));
      const TileRef& r = batch[i];
      if (r.made) {
        level0Tile(r.tx, r.ty, &made, &made_tile_bound);
        visit(made, made_tile_bound, r.bx, r.by);
      } else {
        visit(blocks.data[r.index], bounds.data[r.index], r.bx, r.by);
      }
    }
    n = 0;
  };
  auto accept = [&](int li, int tx, int ty, size_t index, double bx, double by, double d2) {
    batch[n++] = {index, bx, by, d2, tx, ty, li == 0 && virtual_level0};
    if (n == kBatch) flush();
  };
  const Level& top = levels[t.coarsest];
  const double side = top.tile * step;
  auto periods = [&](double u, double size, int64_t* p0, int64_t* p1) {
    if (!repeat) {
      *p0 = *p1 = 0;
      return;
    }
    *p0 = int64_t(std::floor((u - t.reach) / size));
    *p1 = int64_t(std::floor((u + t.reach) / size));
  };
  int64_t py0, py1, px0, px1;
  periods(t.uy, double(height), &py0, &py1);
  periods(t.ux, double(width), &px0, &px1);
  for (int64_t py = py0; py <= py1; ++py) {
    const double oy = double(py) * height;
    const double ly0 = t.uy - t.reach - oy, ly1 = t.uy + t.reach - oy;
    const int ty0 = int(std::max(0.0, std::floor(ly0 / side))),
              ty1 = int(std::min(double(top.tiles_y - 1), std::floor(ly1 / side)));
    for (int64_t px = px0; px <= px1; ++px) {
      const double ox = double(px) * width;
      const double lx0 = t.ux - t.reach - ox, lx1 = t.ux + t.reach - ox;
      const int tx0 = int(std::max(0.0, std::floor(lx0 / side))),
                tx1 = int(std::min(double(top.tiles_x - 1), std::floor(lx1 / side)));
      for (int ty = ty0; ty <= ty1; ++ty) {
        for (int tx = tx0; tx <= tx1; ++tx) visitNode(t, t.coarsest, tx, ty, t.ux - ox, t.uy - oy, accept);
      }
    }
  }
  flush();
}

// Tile (tx, ty) of level li, or its children when the cut takes this region from a finer level:
// a tile li - finest levels coarser than the footprint's is taken where its nearest point is at
// least sqrt(2 kCoarsenStep (li - finest)) footprint stds from the centre.
template <typename Accept>
void LobeNdf::Impl::visitNode(const Terms& t, int li, int tx, int ty, double ux, double uy, Accept& accept) const {
  const Level& l = levels[li];
  const double side = l.tile * step;
  double bx, by, dx, dy;
  flakes::tileGap(ux, uy, tx, ty, side, &bx, &by, &dx, &dy);
  if (dx > t.reach || dy > t.reach) return;
  const size_t index = l.first + size_t(ty) * size_t(l.tiles_x) + size_t(tx);
  const double d2 = dx * dx + dy * dy;
  if (li == t.finest || d2 >= cutLimit(t, li)) {
    accept(li, tx, ty, index, bx, by, d2);
    return;
  }
  if (li == 1 && t.skip_inner) return;  // an inner tile: the exact flakes answer it
  const Level& c = levels[li - 1];
  for (int cy = 2 * ty; cy < std::min(c.tiles_y, 2 * ty + 2); ++cy) {
    for (int cx = 2 * tx; cx < std::min(c.tiles_x, 2 * tx + 2); ++cx) visitNode(t, li - 1, cx, cy, ux, uy, accept);
  }
}

double LobeNdf::Impl::lobeAt(const Block& b, int i, double bx, double by, double sp2, flakes::Lobe* g) const {
  const double a00 = double(b.uxx[i]) + sp2, a01 = b.uxy[i], a11 = double(b.uyy[i]) + sp2;
  const double det_a = a00 * a11 - a01 * a01;
  const double i00 = a11 / det_a, i01 = -a01 / det_a, i11 = a00 / det_a;
  const double dx = bx - double(b.cx[i]), dy = by - double(b.cy[i]);
  const double gx = i00 * dx + i01 * dy, gy = i01 * dx + i11 * dy;
  const double spatial = 0.5 * (dx * gx + dy * gy);
  const double s00 = b.s00[i], s01 = b.s01[i], s10 = b.s10[i], s11 = b.s11[i];
  const double h00 = s00 * i00 + s01 * i01, h01 = s00 * i01 + s01 * i11;
  const double h10 = s10 * i00 + s11 * i01, h11 = s10 * i01 + s11 * i11;
  g->mx = double(b.mx[i]) + s00 * gx + s01 * gy;
  g->my = double(b.my[i]) + s10 * gx + s11 * gy;
  g->cxx = std::max(double(b.sxx[i]) - (h00 * s00 + h01 * s01), 1e-12);
  g->cxy = double(b.sxy[i]) - (h00 * s10 + h01 * s11);
  g->cyy = std::max(double(b.syy[i]) - (h10 * s10 + h11 * s11), 1e-12);
  const double lim = std::sqrt(g->cxx * g->cyy) * 0.999999;
  g->cxy = std::clamp(g->cxy, -lim, lim);
  if (spatial > kMaxSpatial) return 0.0;
  return kWindowNorm * double(b.w[i]) * std::exp(-spatial) / (kTwoPi * std::sqrt(det_a));
}

template <typename Visit>
void LobeNdf::Impl::forEachLobe(const Block& b, const Bound& bound, double bx, double by, double sp2,
                                Visit&& visit) const {
  for (uint32_t i = 0; i < bound.count; ++i) {
    flakes::Lobe g;
    const double w = lobeAt(b, int(i), bx, by, sp2, &g);
    if (w > 0.0) visit(g, w);
  }
}

double LobeNdf::Impl::laneWeights(const Block& b, const Bound& bound, double bx, double by, double sp2,
                                  float* lanes) const {
  // The kernel (lobe_kernel.inc) in whole vectors; lanes past the count are 0 and add nothing.
  laneWeightKernel(flakes::hasAvx2(), b, int(bound.count), float(sp2), float(bx), float(by),
                   float(kWindowNorm / kTwoPi), float(kMaxSpatial), lanes);
  double sum = 0.0;
  for (uint32_t h = 0; h < bound.count; h += 4)
    sum += (double(lanes[h]) + double(lanes[h + 1])) + (double(lanes[h + 2]) + double(lanes[h + 3]));
  return sum;
}

double LobeNdf::Impl::evalAt(const Terms& t, double sx, double sy) const {
  if (t.exact_mode) {
    double v = 0.0;
    FlakeNdfAccess::windowedEval(*exact, {t.ux, t.uy, t.sigma}, {sx, sy}, kWindowSigmas, &v);
    return v * kWindowNorm;
  }
  // The kernel (lobe_kernel.inc) on the tiles whose lobes may reach s; the lanes kept by its
  // first pass are evaluated and summed (in double, four running sums in a fixed order) whenever
  // the list fills up, and at the end.
  KernelTerms c;
  c.sp2 = float(t.sp2);
  c.sx = float(sx);
  c.sy = float(sy);
  c.spatial_cut = float(kMaxSpatial);
  c.keep_cut = float(kMaxExponent) + 0.01f;
  const bool wide = flakes::hasAvx2();
  LaneList list;
  int n = 0;
  double sums[4] = {0.0, 0.0, 0.0, 0.0};
  auto drain = [&] {
    const int padded = (n + 15) & ~15;
    for (int i = n; i < padded; ++i) {
      list.spatial[i] = 1e30f;
      list.num[i] = 0.0f;
      list.det_c[i] = list.det_ac[i] = 1.0f;
      list.w[i] = 0.0f;
    }
    laneValues(wide, &list, padded, float(kMaxExponent));
    for (int i = 0; i < n; i += 4) {
      sums[0] += double(list.spatial[i]);
      sums[1] += double(list.spatial[i + 1]);
      sums[2] += double(list.spatial[i + 2]);
      sums[3] += double(list.spatial[i + 3]);
    }
    n = 0;
  };
  // Every tile of the cut goes to the kernel. A test of each tile's box of lobe means (widened by
  // |S_su A^-1 (u_Q - c)|, against its largest tr S_ss) skipped few of them and cost more than it
  // saved: without it eval takes 0.69-0.96x the time at 12-40 texels on the README's maps (leather
  // and curved scratches 0.73-0.78x at 24-40, sharp flakes 0.69-0.85x at 24, brushed and bumps
  // 0.90-0.96x), the same lanes kept and summed in the same order.
  forEachTile(t, [&](const Block& b, const Bound& bound, double bx, double by) {
    n = keepLanes(wide, b, int(bound.count), c, float(bx), float(by), &list, n);
    if (n > kLaneList - kLanes) drain();
  });
  drain();
  const double lobes_value = ((sums[0] + sums[1]) + (sums[2] + sums[3])) * kWindowNorm / (kTwoPi * kTwoPi);
  return t.inner_exact ? lobes_value + innerEval(t, sx, sy) : lobes_value;
}

double LobeNdf::Impl::innerEval(const Terms& t, double sx, double sy) const {
  double v = 0.0;
  FlakeNdfAccess::windowedEval(*exact, t.fp, {sx, sy}, kWindowSigmas, &v, &t.inner_cut);
  return v * kWindowNorm;
}

double LobeNdf::Impl::innerMass(const Terms& t) const {
  double m = 0.0;
  FlakeNdfAccess::windowedMass(*exact, t.fp, kWindowSigmas, &m, &t.inner_cut);
  return m * kWindowNorm;
}

double LobeNdf::Impl::massOf(const Terms& t) const {
  if (t.exact_mode) {
    double m = 0.0;
    FlakeNdfAccess::windowedMass(*exact, {t.ux, t.uy, t.sigma}, kWindowSigmas, &m);
    return m * kWindowNorm;
  }
  double sum = 0.0;
  float lanes[kLanes];
  forEachTile(t, [&](const Block& b, const Bound& bound, double bx, double by) {
    sum += laneWeights(b, bound, bx, by, t.sp2, lanes);
  });
  return t.inner_exact ? sum + innerMass(t) : sum;
}

LobeNdf::LobeNdf() = default;
LobeNdf::~LobeNdf() = default;

RuntimeStatus LobeNdf::build(const TexelSource& source, int rate, double sigma_r, int lobes_per_tile, int resolution) {
  return LobeNdfAccess::build(*this, source, rate, sigma_r, lobes_per_tile, resolution, nullptr);
}

RuntimeStatus LobeNdf::setTileRatio(double ratio) {
  if (!(ratio >= kMinLobeTileRatio && ratio <= kMaxLobeTileRatio)) return RuntimeStatus::kInvalidArgument;
  if (!impl_) return RuntimeStatus::kInvalidArgument;
  impl_->tile_ratio = ratio;
  return RuntimeStatus::kOk;
}

double LobeNdf::tileRatio() const { return impl_ ? impl_->tile_ratio : kDefaultLobeTileRatio; }

RuntimeStatus LobeNdfAccess::build(LobeNdf& lobes, const TexelSource& source, int rate, double sigma_r,
                                   int lobes_per_tile, int resolution, const FlakeNdf* shared) {
  lobes.impl_.reset();
  if (shared && !shared->isBuilt()) return RuntimeStatus::kInvalidArgument;
  auto impl = std::unique_ptr<LobeNdf::Impl>(new (std::nothrow) LobeNdf::Impl());
  if (!impl) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus s = impl->build(source, rate, sigma_r, lobes_per_tile, resolution, shared); s != RuntimeStatus::kOk)
    return s;
  lobes.impl_ = std::move(impl);
  return RuntimeStatus::kOk;
}

bool LobeNdf::isBuilt() const { return impl_ != nullptr; }
void LobeNdf::prepare() const {
  if (impl_) impl_->levelBuilt(impl_->level_count - 1);
}
int LobeNdf::resolution() const { return impl_ ? impl_->res : 0; }
MapSize LobeNdf::mapSize() const { return impl_ ? MapSize{impl_->width, impl_->height} : MapSize{}; }
MapWrap LobeNdf::wrap() const { return impl_ && !impl_->repeat ? MapWrap::kClamp : MapWrap::kRepeat; }
uint64_t LobeNdf::memoryBytes() const {
  if (!impl_ || impl_->level_count == 0) return 0;
  return uint64_t(impl_->blocks.size) * sizeof(Block) + uint64_t(impl_->bounds.size) * sizeof(Bound) +
         uint64_t(impl_->normals.size) * sizeof(float);
}

int LobeNdf::tileFor(double sigma) const { return impl_ ? impl_->levels[impl_->levelFor(sigma)].tile : 0; }

FootprintRange LobeNdf::footprintRange() const {
  FootprintRange r;
  if (!impl_) return r;
  // The largest sigma whose window on the top level spans at most kMaxWindowTiles tiles per side:
  // 2 (4 sqrt(sigma^2 + sigma_h^2) + side) / side + 2 <= kMaxWindowTiles.
  const Impl& m = *impl_;
  const double side = m.levels[m.level_count - 1].tile * m.step;
  const double reach = (double(kMaxWindowTiles) - 2.0) * side / 2.0 - side;
  r.clustered_min_sigma = 0.0;
  r.clustered_max_sigma =
      std::floor(std::sqrt(std::max(0.0, reach * reach / (kWindowSigmas * kWindowSigmas) - m.sigma_h2)));
  return r;
}

using flakes::inSquare;

RuntimeStatus LobeNdf::eval(const Footprint& footprint, const SPoint& s, double* value) const {
  return flakes::pointEval<Terms>(impl_.get(), footprint, s, value);
}

bool LobeNdfAccess::exactWindow(const LobeNdf& lobes, double sigma, double* window_sigmas, double* norm) {
  const LobeNdf::Impl* m = lobes.impl_.get();
  if (!m || !m->exact || !(sigma >= 0.0)) return false;
  Terms t;
  m->chooseLevels(sigma, &t);
  if (!t.exact_mode) return false;
  *window_sigmas = kWindowSigmas;
  *norm = kWindowNorm;
  return true;
}

RuntimeStatus LobeNdf::mass(const Footprint& footprint, double* value) const {
  return flakes::pointMass<Terms>(impl_.get(), footprint, value);
}

RuntimeStatus LobeNdf::pdf(const Footprint& footprint, const SPoint& s, double* value) const {
  return flakes::pointPdf<Terms>(impl_.get(), footprint, s, value);
}

RuntimeStatus LobeNdf::average(const Footprint& footprint, const SRect& rect, double* value) const {
  if (!impl_ || !value || !validFootprint(footprint) || !validRect(rect)) return RuntimeStatus::kInvalidArgument;
  const Impl& m = *impl_;
  Terms t;
  if (!m.terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  t.skip_inner = false;  // the inner tiles as level-0 lobes (the flakes, one lobe each)
  const double x0 = std::max(rect.x0, -1.0), x1 = std::min(rect.x1, 1.0);
  const double y0 = std::max(rect.y0, -1.0), y1 = std::min(rect.y1, 1.0);
  double integral = 0.0;
  if (x1 > x0 && y1 > y0) {
    m.forEachTile(t, [&](const Block& b, const Bound& bound, double bx, double by) {
      m.forEachLobe(b, bound, bx, by, t.sp2, [&](const flakes::Lobe& g, double weight) {
        integral += weight * flakes::lobeRectProbability(g, x0, x1, y0, y1, flakes::LobeAccuracy::kImage);
      });
    });
  }
  *value = integral / ((rect.x1 - rect.x0) * (rect.y1 - rect.y0));
  return RuntimeStatus::kOk;
}

RuntimeStatus LobeNdf::addImage(const Footprint& footprint, double weight, float* out, size_t out_count) const {
  if (!impl_) return RuntimeStatus::kInvalidArgument;
  const Impl& m = *impl_;
  const size_t n = size_t(m.res) * size_t(m.res);
  if (!out || out_count < n || !validFootprint(footprint) || !std::isfinite(weight))
    return RuntimeStatus::kInvalidArgument;
  Terms t;
  if (!m.terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  t.skip_inner = false;  // as average
  const double bin = 2.0 / m.res;
  const double to_density = weight / (bin * bin);
  m.forEachTile(t, [&](const Block& b, const Bound& bound, double bx, double by) {
    m.forEachLobe(b, bound, bx, by, t.sp2, [&](const flakes::Lobe& g, double w) {
      flakes::splatLobe(g, to_density * w, m.res, out, flakes::LobeAccuracy::kImage);
    });
  });
  return RuntimeStatus::kOk;
}

RuntimeStatus LobeNdf::sample(const Footprint& footprint, double u1, double u2, NdfSample* out) const {
  return LobeNdfAccess::sample(*this, footprint, u1, u2, out, true);
}

RuntimeStatus LobeNdfAccess::sample(const LobeNdf& lobes, const Footprint& footprint, double u1, double u2,
                                    NdfSample* out, bool with_pdf, const double* known_mass) {
  if (!lobes.impl_ || !out || !validFootprint(footprint) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  const LobeNdf::Impl& m = *lobes.impl_;
  Terms t;
  if (!m.terms(footprint, &t)) return RuntimeStatus::kInvalidArgument;
  // The clustered levels' mass tile by tile (massOf's sum, in its order), kept for the pick.
  double tile_mass[kMaxSampleTiles];
  int tiles = 0;
  float lanes[kLanes];
  double total = 0.0;
  const double inner = t.inner_exact ? m.innerMass(t) : 0.0;  // the exact flakes' share
  bool outer_mass = true;
  if (known_mass) {
    total = *known_mass;
    tiles = kMaxSampleTiles + 1;  // no masses kept: the pick weighs the tiles as it walks
  } else if (t.exact_mode) {
    total = m.massOf(t);
  } else {
    m.forEachTile(t, [&](const Block& b, const Bound& bound, double bx, double by) {
      const double w = m.laneWeights(b, bound, bx, by, t.sp2, lanes);
      total += w;
      if (tiles < kMaxSampleTiles) tile_mass[tiles] = w;
      ++tiles;
    });
    outer_mass = total > 0.0;
    if (t.inner_exact) total += inner;  // massOf's order
  }
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
  auto finish = [&](const flakes::Lobe& g, double v1, double v2) {
    flakes::lobePoint(g, v1, v2, &out->s.x, &out->s.y);
    out->pdf = with_pdf && inSquare(out->s) ? m.evalAt(t, out->s.x, out->s.y) / total : 0.0;
    return RuntimeStatus::kOk;
  };
  if (t.exact_mode) {  // a flake of the window by its weight
    flakes::Lobe g;
    double v1 = 0.5, v2 = 0.5;
    if (FlakeNdfAccess::windowedPick(*m.exact, {t.ux, t.uy, t.sigma}, kWindowSigmas, u1, u2, total / kWindowNorm, &g,
                                     &v1, &v2) != RuntimeStatus::kOk)
      return RuntimeStatus::kInvalidArgument;
    return finish(g, v1, v2);
  }
  // The exact flakes' share first (a target below its mass, or every lobe without weight), then a
  // tile in proportion to its mass, then a lane of it in proportion to its weight (the sums of
  // massOf, tile by tile), u1 rescaled within the lane. Rounding that leaves the target past the
  // end takes the last lobe of the last tile with mass.
  double target = u1 * total, v1 = 0.99999999999999989;
  if (inner > 0.0 && (target < inner || !outer_mass)) {
    flakes::Lobe g;
    double w1 = 0.5, w2 = 0.5;
    if (FlakeNdfAccess::windowedPick(*m.exact, t.fp, kWindowSigmas, std::min(target / inner, v1), u2,
                                     inner / kWindowNorm, &g, &w1, &w2, &t.inner_cut) != RuntimeStatus::kOk)
      return RuntimeStatus::kInvalidArgument;
    return finish(g, w1, w2);
  }
  target -= inner;
  flakes::Lobe picked{0.0, 0.0, 1.0, 0.0, 1.0};
  const Block* last_block = nullptr;
  const Bound* last_bound = nullptr;
  double last_bx = 0.0, last_by = 0.0;
  bool found = false;
  auto pickIn = [&](const Block& b, const Bound& bound, double bx, double by) {
    m.laneWeights(b, bound, bx, by, t.sp2, lanes);
    int lane = -1;
    for (uint32_t i = 0; i < bound.count; ++i) {
      const double w = lanes[i];
      if (!(w > 0.0)) continue;
      lane = int(i);
      if (target < w) {
        v1 = std::clamp(target / w, 0.0, 0.99999999999999989);
        break;
      }
      target -= w;
    }
    m.lobeAt(b, std::max(lane, 0), bx, by, t.sp2, &picked);
    found = true;
  };
  // The tile from the masses kept above (the last with mass when rounding runs past the end),
  // then a second walk of the window to reach it.
  int chosen = -1, last_with_mass = -1;
  if (tiles <= kMaxSampleTiles) {
    for (int k = 0; k < tiles && chosen < 0; ++k) {
      if (!(tile_mass[k] > 0.0)) continue;
      last_with_mass = k;
      if (target < tile_mass[k])
        chosen = k;
      else
        target -= tile_mass[k];
    }
    if (chosen < 0) {
      if (last_with_mass < 0) return RuntimeStatus::kInvalidArgument;  // no tile had mass
      chosen = last_with_mass;
      target = std::numeric_limits<double>::infinity();
    }
  }
  int ordinal = 0;
  m.forEachTile(t, [&](const Block& b, const Bound& bound, double bx, double by) {
    if (found) return;
    if (chosen >= 0) {
      if (ordinal++ == chosen) pickIn(b, bound, bx, by);
      return;
    }
    const double mass = m.laneWeights(b, bound, bx, by, t.sp2, lanes);
    if (!(mass > 0.0)) return;
    if (target < mass) {
      pickIn(b, bound, bx, by);
      return;
    }
    target -= mass;
    last_block = &b;
    last_bound = &bound;
    last_bx = bx;
    last_by = by;
  });
  if (!found) {
    if (!last_block || !last_bound) return RuntimeStatus::kInvalidArgument;  // no tile had mass
    target = std::numeric_limits<double>::infinity();
    pickIn(*last_block, *last_bound, last_bx, last_by);
  }
  return finish(picked, v1, u2);
}

}  // namespace glintbake::runtime
