// SPDX-License-Identifier: Apache-2.0
// Tiny-example assets (formats/SPEC.md 10.8): loading, the tile images, the traversal of the
// examples a footprint reaches and the NdfSource queries over the tiles it keeps.
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/tiny_example_ndf.h>

#include <glintbake/format/binary16.h>
#include <glintbake/format/validate.h>

#include "../flakes/flake_model.h"
#include "../flakes/gaussian_rect.h"
#include "../format_status.h"
#include "../query_args.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <optional>

namespace glintbake::runtime {

using format::TinyExampleRecord;
using format::TinyExampleType;

namespace {

constexpr double kSigmaH = 1.5 / 3.4641016151377544;  // flake spatial std at rate 1 (SPEC.md 10.5)
constexpr double kMinSigma = 1e-3;                    // tile path: smaller footprints are points
constexpr double kNegligible = 1e-15;                 // tiles with less probability are skipped

// Whether the window [c - r, c + r] in units of `unit` stays well inside the int64 range (false
// for NaN and infinities too).
bool windowInRange(double c, double r, double unit) {
  const double lo = (c - r) / unit, hi = (c + r) / unit;
  return std::fabs(lo) < 1e15 && std::fabs(hi) < 1e15;
}
bool inSquare(const SPoint& s) { return s.x >= -1.0 && s.x <= 1.0 && s.y >= -1.0 && s.y <= 1.0; }

// Bin (column, row) of an s-plane point of [-1, 1]^2 in an R x R image.
inline int binColumn(double sx, int res) { return std::clamp(int(std::floor((sx + 1.0) * 0.5 * res)), 0, res - 1); }
inline int binRow(double sy, int res) { return std::clamp(int(std::floor((1.0 - sy) * 0.5 * res)), 0, res - 1); }

// Area of a convex polygon (counter-clockwise or clockwise) clipped to [x0, x1] x [y0, y1].
struct Poly {
  double x[12], y[12];
  int n = 0;
};

void clipAxis(const Poly& in, int axis, double bound, bool keep_below, Poly* out) {
  out->n = 0;
  for (int i = 0; i < in.n; ++i) {
    const int j = (i + 1) % in.n;
    const double a = axis == 0 ? in.x[i] : in.y[i], b = axis == 0 ? in.x[j] : in.y[j];
    const bool ia = keep_below ? a <= bound : a >= bound, ib = keep_below ? b <= bound : b >= bound;
    if (ia) {
      out->x[out->n] = in.x[i];
      out->y[out->n] = in.y[i];
      ++out->n;
    }
    if (ia != ib) {
      const double t = (bound - a) / (b - a);
      out->x[out->n] = in.x[i] + t * (in.x[j] - in.x[i]);
      out->y[out->n] = in.y[i] + t * (in.y[j] - in.y[i]);
      ++out->n;
    }
  }
}

double area(const Poly& p) {
  double a = 0.0;
  for (int i = 0; i < p.n; ++i) {
    const int j = (i + 1) % p.n;
    a += p.x[i] * p.y[j] - p.x[j] * p.y[i];
  }
  return 0.5 * std::fabs(a);
}

// Integral of the piecewise-constant images (weighted sum over `count` of them) over a convex
// polygon of the s-plane.
struct WeightedImage {
  const float* image;
  double weight;
};

// The chord of a convex polygon at height y: [*xl, *xr]; false when the line misses it.
bool chordAt(const Poly& p, double y, double* xl, double* xr) {
  double lo = 1e300, hi = -1e300;
  for (int i = 0; i < p.n; ++i) {
    const int j = (i + 1) % p.n;
    const double ya = p.y[i], yb = p.y[j];
    if ((ya < y && yb < y) || (ya > y && yb > y)) continue;
    if (ya == yb) {
      lo = std::min({lo, p.x[i], p.x[j]});
      hi = std::max({hi, p.x[i], p.x[j]});
      continue;
    }
    const double x = p.x[i] + (y - ya) / (yb - ya) * (p.x[j] - p.x[i]);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  *xl = lo;
  *xr = hi;
  return lo <= hi;
}

double polygonIntegral(const Poly& p, const WeightedImage* images, int count, int res) {
  double lo_x = 1e300, hi_x = -1e300, lo_y = 1e300, hi_y = -1e300;
  for (int i = 0; i < p.n; ++i) {
    lo_x = std::min(lo_x, p.x[i]);
    hi_x = std::max(hi_x, p.x[i]);
    lo_y = std::min(lo_y, p.y[i]);
    hi_y = std::max(hi_y, p.y[i]);
  }
  if (hi_x <= -1.0 || lo_x >= 1.0 || hi_y <= -1.0 || lo_y >= 1.0) return 0.0;
  const double bin = 2.0 / res;
  const int i0 = binColumn(std::max(lo_x, -1.0), res), i1 = binColumn(std::min(hi_x, 1.0), res);
  const int j0 = binRow(std::min(hi_y, 1.0), res), j1 = binRow(std::max(lo_y, -1.0), res);
  double total = 0.0;
  auto binValue = [&](int j, int i) {
    double v = 0.0;
    for (int k = 0; k < count; ++k) v += images[k].weight * double(images[k].image[size_t(j) * res + i]);
    return v;
  };
  Poly band, tmp, cell;
  for (int j = j0; j <= j1; ++j) {
    const double top = 1.0 - j * bin, bottom = 1.0 - (j + 1) * bin;
    clipAxis(p, 1, top, true, &tmp);
    clipAxis(tmp, 1, bottom, false, &band);
    if (band.n < 3) continue;
    // Bins between the chords at the band's top and bottom lie wholly inside the polygon (it is
    // convex): no clipping there.
    double tl = 0.0, tr = -1.0, bl = 0.0, br = -1.0;
    double inner_l = 1e300, inner_r = -1e300;
    if (chordAt(p, top, &tl, &tr) && chordAt(p, bottom, &bl, &br)) {
      inner_l = std::max(tl, bl);
      inner_r = std::min(tr, br);
    }
    for (int i = i0; i <= i1; ++i) {
      const double left = -1.0 + i * bin, right = -1.0 + (i + 1) * bin;
      if (left >= inner_l && right <= inner_r) {
        total += binValue(j, i) * ((right - left) * (top - bottom));
        continue;
      }
      clipAxis(band, 0, left, false, &tmp);
      clipAxis(tmp, 0, right, true, &cell);
      if (cell.n < 3) continue;
      const double a = area(cell);
      if (!(a > 0.0)) continue;
      total += binValue(j, i) * a;
    }
  }
  return total;
}

// Probability of a Gaussian N(mu, Sigma) over the box [x0, x1] x [y0, y1].
struct Gauss {
  double mx, my, cxx, cxy, cyy;
  double sx, sy;
  bool separable;
  double lambda_min;
};

Gauss makeGauss(double mx, double my, double cxx, double cxy, double cyy) {
  Gauss g{mx, my, cxx, cxy, cyy, std::sqrt(cxx), std::sqrt(cyy), false, 0.0};
  g.separable = std::fabs(cxy) <= 1e-12 * std::max(cxx, cyy);
  const double tr = 0.5 * (cxx + cyy), dd = std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
  g.lambda_min = std::max(tr - dd, 1e-300);
  return g;
}

double boxProbability(const Gauss& g, double x0, double x1, double y0, double y1) {
  if (g.separable) {
    const double px = flakes::normalCdf((x1 - g.mx) / g.sx) - flakes::normalCdf((x0 - g.mx) / g.sx);
    if (!(px > 0.0)) return 0.0;
    return px * (flakes::normalCdf((y1 - g.my) / g.sy) - flakes::normalCdf((y0 - g.my) / g.sy));
  }
  const flakes::Lobe lobe{g.mx, g.my, g.cxx, g.cxy, g.cyy};
  return flakes::lobeRectProbability(lobe, x0, x1, y0, y1, flakes::LobeAccuracy::kImage);
}

void mul(const double a[4], const double b[4], double out[4]) {
  const double r[4] = {a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2],
                       a[2] * b[1] + a[3] * b[3]};
  std::memcpy(out, r, sizeof r);
}

}  // namespace

// An example's view of the s-plane: s_e = B s (B = F M^T F), s = A s_e, densities times |det M|.
struct TinyExampleNdf::Frame {
  double b[4], a[4];
  double jac = 1.0;
  bool grid = false;  // B maps bins onto bins (a signed permutation)
};

namespace {

TinyExampleNdf::Frame makeFrame(const double m[4]) {
  TinyExampleNdf::Frame f;
  f.b[0] = m[0];
  f.b[1] = -m[2];
  f.b[2] = -m[1];
  f.b[3] = m[3];
  format::tinyInvert(f.b, f.a);
  f.jac = std::fabs(m[0] * m[3] - m[1] * m[2]);
  f.grid = TransformedExampleTexels::isGridTransform(m);
  return f;
}

const double kIdentity[4] = {1.0, 0.0, 0.0, 1.0};

// ---------------------------------------------------------------------------------------------
// Overlapping layouts: the examples that may take points of one example, and the share of a tile
// the example owns under the nearest-centre rule (format::tinyNearer).

constexpr int kMaxNeighbours = (4 * format::kMaxTinyOverlapReach + 1) * (4 * format::kMaxTinyOverlapReach + 1);

struct Neighbour {
  format::TinyPlacement p;
  double box[4];  // x0, x1, y0, y1 of its square on the plane
};

struct OwnedExample {
  format::TinyPlacement self;
  Neighbour others[kMaxNeighbours];
  int count = 0;
};

// Bounding box of the example's square on the plane.
void exampleBox(const format::TinyExampleRecord& r, const format::TinyPlacement& p, double box[4]) {
  const double half = 0.5 * double(r.example_size);
  const double ex = (std::fabs(p.matrix[0]) + std::fabs(p.matrix[1])) * half;
  const double ey = (std::fabs(p.matrix[2]) + std::fabs(p.matrix[3])) * half;
  box[0] = p.centre[0] - ex;
  box[1] = p.centre[0] + ex;
  box[2] = p.centre[1] - ey;
  box[3] = p.centre[1] + ey;
}

bool boxesMeet(const double a[4], const double b[4]) {
  return a[0] <= b[1] && b[0] <= a[1] && a[2] <= b[3] && b[2] <= a[3];
}

// The examples whose squares meet p's (their cells lie within twice the reach of p's cell). False
// when there are none: p owns all of its square.
// The placements of a band of rows of cells, each computed once per query: the rows [j - span,
// j + span] around the window row j being walked (the rows its examples' neighbours lie in), over
// the window's columns widened by span. Rows slide down as the walk does; a cell outside the band
// is computed each time it is asked for.
struct PlacementCache {
  static constexpr int kCells = 576;
  const format::TinyExampleRecord* record = nullptr;
  const format::TinyLayout* layout = nullptr;
  int64_t i0 = 0, width = 0;     // columns [i0, i0 + width); width 0: nothing cached
  int64_t rows = 0;              // rows held: 2 span + 1
  int64_t first = 0, last = -1;  // rows [first, last] are loaded; row j lives at slot j mod rows
  format::TinyPlacement cells[kCells];

  // Columns [ci0, ci1], rows span either side of the walked row.
  void begin(int64_t ci0, int64_t ci1, int span) {
    rows = 2 * int64_t(span) + 1;
    width = ci1 - ci0 + 1;
    i0 = ci0;
    first = 0;
    last = -1;
    if (width * rows > kCells) width = 0;
  }
  // Makes rows [j - span, j + span] resident (j only ever grows during a walk).
  void walkTo(int64_t j) {
    if (width == 0) return;
    const int64_t span = rows / 2, lo = j - span, hi = j + span;
    if (last < first || lo > last || lo < first) last = lo - 1;  // nothing of the new band resident
    first = lo;
    for (int64_t row = last + 1; row <= hi; ++row) {
      format::TinyPlacement* slot = cells + slotOf(row) * width;
      for (int64_t i = 0; i < width; ++i) slot[i] = format::tinyCellPlacement(*record, i0 + i, row, layout);
    }
    last = hi;
  }
  format::TinyPlacement at(int64_t i, int64_t j) const {
    if (width > 0 && i >= i0 && i < i0 + width && j >= first && j <= last) return cells[slotOf(j) * width + (i - i0)];
    return format::tinyCellPlacement(*record, i, j, layout);
  }

 private:
  int64_t slotOf(int64_t row) const { return ((row % rows) + rows) % rows; }
};

bool gatherNeighbours(const format::TinyExampleRecord& r, const PlacementCache& cache, const format::TinyPlacement& p,
                      int reach, OwnedExample* out) {
  out->self = p;
  out->count = 0;
  double own[4];
  exampleBox(r, p, own);
  const int span = 2 * reach;
  for (int64_t j = p.cell_y - span; j <= p.cell_y + span; ++j) {
    for (int64_t i = p.cell_x - span; i <= p.cell_x + span; ++i) {
      if (i == p.cell_x && j == p.cell_y) continue;
      const format::TinyPlacement q = cache.at(i, j);
      if (!q.present) continue;
      Neighbour& nb = out->others[out->count];
      exampleBox(r, q, nb.box);
      if (!boxesMeet(own, nb.box)) continue;
      nb.p = q;
      ++out->count;
    }
  }
  return out->count > 0;
}

double dist2(const double c[2], double x, double y) {
  const double dx = x - c[0], dy = y - c[1];
  return dx * dx + dy * dy;
}

// The plane point of example frame point (vx, vy).
void toPlane(const format::TinyExampleRecord& r, const format::TinyPlacement& p, double vx, double vy, double* x,
             double* y) {
  const double h = 0.5 * double(r.example_size);
  *x = p.centre[0] + p.matrix[0] * (vx - h) + p.matrix[1] * (vy - h);
  *y = p.centre[1] + p.matrix[2] * (vx - h) + p.matrix[3] * (vy - h);
}

// Whether the example owns the plane point (x, y) of its own square.
bool ownsPoint(const format::TinyExampleRecord& r, const OwnedExample& e, double x, double y) {
  const double de = dist2(e.self.centre, x, y);
  double local[2];
  for (int k = 0; k < e.count; ++k) {
    const Neighbour& nb = e.others[k];
    if (x < nb.box[0] || x > nb.box[1] || y < nb.box[2] || y > nb.box[3]) continue;
    if (format::tinyNearer(de, e.self, dist2(nb.p.centre, x, y), nb.p)) continue;
    if (format::tinyContains(r, nb.p, x, y, local)) return false;
  }
  return true;
}

enum class Ownership { kFull, kNone, kMixed };

// The tile [x0, x0 + t]^2 of the example's frame: owned wholly, taken wholly by one other example,
// or shared. Half-planes of nearer points and the squares are convex: the corners decide.
Ownership classifyTile(const format::TinyExampleRecord& r, const OwnedExample& e, double x0, double y0, double t) {
  double cx[4], cy[4], quad[4] = {1e300, -1e300, 1e300, -1e300};
  for (int k = 0; k < 4; ++k) {
    toPlane(r, e.self, x0 + (k & 1) * t, y0 + (k >> 1) * t, &cx[k], &cy[k]);
    quad[0] = std::min(quad[0], cx[k]);
    quad[1] = std::max(quad[1], cx[k]);
    quad[2] = std::min(quad[2], cy[k]);
    quad[3] = std::max(quad[3], cy[k]);
  }
  bool mixed = false;
  double local[2];
  for (int k = 0; k < e.count; ++k) {
    const Neighbour& nb = e.others[k];
    if (!boxesMeet(quad, nb.box)) continue;
    int self_wins = 0, inside = 0;
    for (int c = 0; c < 4; ++c) {
      self_wins +=
          format::tinyNearer(dist2(e.self.centre, cx[c], cy[c]), e.self, dist2(nb.p.centre, cx[c], cy[c]), nb.p) ? 1
                                                                                                                 : 0;
      inside += format::tinyContains(r, nb.p, cx[c], cy[c], local) ? 1 : 0;
    }
    if (self_wins == 4) continue;
    if (self_wins == 0 && inside == 4) return Ownership::kNone;
    mixed = true;
  }
  return mixed ? Ownership::kMixed : Ownership::kFull;
}

// The footprint-weighted share of the tile the example owns, from s x s points of the tile.
double ownedShare(const format::TinyExampleRecord& r, const OwnedExample& e, const Gauss& g, double x0, double y0,
                  double t, int s) {
  const double det = g.cxx * g.cyy - g.cxy * g.cxy;
  const double ixx = g.cyy / det, ixy = -g.cxy / det, iyy = g.cxx / det;
  double total = 0.0, owned = 0.0;
  int count = 0, owned_count = 0;
  for (int b = 0; b < s; ++b) {
    for (int a = 0; a < s; ++a) {
      const double vx = x0 + (a + 0.5) * t / s, vy = y0 + (b + 0.5) * t / s;
      const double dx = vx - g.mx, dy = vy - g.my;
      const double w = det > 0.0 ? std::exp(-0.5 * (ixx * dx * dx + 2.0 * ixy * dx * dy + iyy * dy * dy)) : 0.0;
      double x, y;
      toPlane(r, e.self, vx, vy, &x, &y);
      const bool mine = ownsPoint(r, e, x, y);
      total += w;
      ++count;
      if (mine) {
        owned += w;
        ++owned_count;
      }
    }
  }
  return total > 1e-300 ? owned / total : double(owned_count) / double(count);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Tile images.

RuntimeStatus tinyTileImage(const float* texels, int n, bool repeats, double sigma_r, int res, int x0, int y0, int side,
                            float* out) {
  if (!texels || !out || n < 1 || n > 65536 || res < 2 || res > 4096 || side < 1 || x0 < 0 || y0 < 0 || x0 + side > n ||
      y0 + side > n || !(sigma_r > 0.0 && sigma_r <= 1.0))
    return RuntimeStatus::kInvalidArgument;
  std::fill(out, out + size_t(res) * res, 0.0f);
  const double bin = 2.0 / res;
  const double weight = 1.0 / (double(side) * side * bin * bin);
  const double r2 = sigma_r * sigma_r, h2 = kSigmaH * kSigmaH;
  for (int y = y0; y < y0 + side; ++y) {
    for (int x = x0; x < x0 + side; ++x) {
      float nk[2], j[4];
      flakes::flakeAt(texels, n, n, repeats, x + 0.5, y + 0.5, nk, j);
      const double j0 = j[0], j1 = j[1], j2 = j[2], j3 = j[3];
      const flakes::Lobe g{double(nk[0]), double(nk[1]), r2 + h2 * (j0 * j0 + j1 * j1), h2 * (j0 * j2 + j1 * j3),
                           r2 + h2 * (j2 * j2 + j3 * j3)};
      flakes::splatLobe(g, weight, res, out);
    }
  }
  return RuntimeStatus::kOk;
}

// ---------------------------------------------------------------------------------------------
// The transformed example as a texel grid.

bool TransformedExampleTexels::isGridTransform(const double m[4]) {
  for (int i = 0; i < 4; ++i)
    if (m[i] != 0.0 && m[i] != 1.0 && m[i] != -1.0) return false;
  return std::fabs(m[0] * m[3] - m[1] * m[2]) == 1.0 && (m[0] == 0.0) == (m[3] == 0.0);
}

TransformedExampleTexels::TransformedExampleTexels(const float* texels, int n, bool repeats, const double matrix[4])
    : texels_(texels), n_(n), repeats_(repeats) {
  const double* m = isGridTransform(matrix) ? matrix : kIdentity;
  for (int i = 0; i < 4; ++i) m_[i] = int(m[i]);
  // The image of the corner (n, n): the square M [0, n]^2 starts at min(0, that) per axis.
  off_[0] = std::min(0.0, double((m_[0] + m_[1]) * n));
  off_[1] = std::min(0.0, double((m_[2] + m_[3]) * n));
}

void TransformedExampleTexels::normal(int x, int y, float out[2]) const {
  // Texel centre in the plane relative to M's image of the example corner, back through M^-1 = M^T.
  const double gx = off_[0] + x + 0.5, gy = off_[1] + y + 0.5;
  const int vx = int(std::floor(m_[0] * gx + m_[2] * gy)), vy = int(std::floor(m_[1] * gx + m_[3] * gy));
  const float* t = texels_ + (size_t(std::clamp(vy, 0, n_ - 1)) * n_ + size_t(std::clamp(vx, 0, n_ - 1))) * 2;
  // A = F M^-T F = F M F for a signed permutation.
  const double a0 = m_[0], a1 = -m_[1], a2 = -m_[2], a3 = m_[3];
  out[0] = float(a0 * t[0] + a1 * t[1]);
  out[1] = float(a2 * t[0] + a3 * t[1]);
}

// ---------------------------------------------------------------------------------------------
// A rectangle of the plane as a normal map.

TinyPlaneTexels::TinyPlaneTexels(const TinyExampleNdf& asset, int64_t x0, int64_t y0, int width, int height)
    : asset_(asset), x0_(x0), y0_(y0), width_(std::max(1, width)), height_(std::max(1, height)) {}

bool TinyPlaneTexels::texel(int x, int y, float out[2]) const {
  out[0] = out[1] = 0.0f;
  const float* texels = asset_.texels();
  if (!texels) return false;
  const format::TinyExampleRecord& r = asset_.record();
  const int n = int(r.example_size);
  double local[2];
  const format::TinyPlacement p =
      format::tinyOwner(r, double(x0_ + x) + 0.5, double(y0_ + y) + 0.5, local, asset_.layout());
  if (!p.present) return false;
  // Bilinear between the texel centres (k + 1/2), the example repeating with its size.
  const double fx = local[0] - 0.5, fy = local[1] - 0.5;
  const double ix = std::floor(fx), iy = std::floor(fy);
  const double tx = fx - ix, ty = fy - iy;
  const int x_lo = ((int(ix) % n) + n) % n, y_lo = ((int(iy) % n) + n) % n;
  const int x_hi = (x_lo + 1) % n, y_hi = (y_lo + 1) % n;
  double e[2];
  for (int c = 0; c < 2; ++c) {
    const double a = texels[(size_t(y_lo) * n + x_lo) * 2 + c], b = texels[(size_t(y_lo) * n + x_hi) * 2 + c];
    const double d = texels[(size_t(y_hi) * n + x_lo) * 2 + c], f = texels[(size_t(y_hi) * n + x_hi) * 2 + c];
    // Exact at texel centres (tx = ty = 0): no rounding from the weights.
    const double top = tx == 0.0 ? a : a + tx * (b - a), bottom = tx == 0.0 ? d : d + tx * (f - d);
    e[c] = ty == 0.0 ? top : top + ty * (bottom - top);
  }
  const TinyExampleNdf::Frame frame = makeFrame(p.matrix);
  double sx = frame.a[0] * e[0] + frame.a[1] * e[1], sy = frame.a[2] * e[0] + frame.a[3] * e[1];
  const double len = std::sqrt(sx * sx + sy * sy);
  if (len > kTinyMaxMaterialisedSlope) {
    sx *= kTinyMaxMaterialisedSlope / len;
    sy *= kTinyMaxMaterialisedSlope / len;
  }
  out[0] = float(sx);
  out[1] = float(sy);
  return true;
}

// ---------------------------------------------------------------------------------------------
// Loading.

TinyExampleNdf::TinyExampleNdf() = default;
TinyExampleNdf::~TinyExampleNdf() = default;

RuntimeStatus TinyExampleNdf::open(const char* path) {
  if (!path) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (format::ContainerStatus st = reader.open(path); st != format::ContainerStatus::kOk) return fromFormatStatus(st);
  return load(reader);
}

RuntimeStatus TinyExampleNdf::openMemory(const void* data, size_t size) {
  if (!data) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (format::ContainerStatus st = reader.openMemory(data, size); st != format::ContainerStatus::kOk)
    return fromFormatStatus(st);
  return load(reader);
}

namespace {

RuntimeStatus readSized(const format::Reader& reader, uint32_t type, uint64_t key, uint64_t size,
                        std::vector<uint8_t>* bytes) {
  const int idx = reader.find(type, key);
  if (idx < 0 || reader.sections()[size_t(idx)].raw_size != size) return RuntimeStatus::kInvalidAsset;
  return fromFormatStatus(reader.readSection(size_t(idx), bytes));
}

// Integral of each row of an R x R density image, and of the whole image.
double rowIntegrals(const float* img, int res, double* rows) {
  const double bin_area = (2.0 / res) * (2.0 / res);
  double total = 0.0;
  for (int j = 0; j < res; ++j) {
    double r = 0.0;
    for (int i = 0; i < res; ++i) r += double(img[size_t(j) * res + i]);
    rows[j] = r * bin_area;
    total += rows[j];
  }
  return total;
}

}  // namespace

RuntimeStatus TinyExampleNdf::load(const format::Reader& reader) {
  open_ = false;
  flake_texels_.reset();
  flakes_.reset();
  if (reader.kind() != format::AssetKind::kTinyExample) return RuntimeStatus::kWrongKind;
  std::vector<uint8_t> bytes;
  TinyExampleRecord rec;
  if (RuntimeStatus s = readSized(reader, format::kSectionTinyExampleInfo, 0, sizeof rec, &bytes);
      s != RuntimeStatus::kOk)
    return s;
  std::memcpy(&rec, bytes.data(), sizeof rec);
  if (rec.magic == TinyExampleRecord().magic && rec.version > 2) return RuntimeStatus::kUnsupportedVersion;
  if (format::checkTinyExampleRecord(rec)) return RuntimeStatus::kInvalidAsset;
  const int n = int(rec.example_size), res = int(rec.ndf_res);
  if (RuntimeStatus s = readSized(reader, format::kSectionTinyExampleTexels, 0, uint64_t(n) * n * 8, &bytes);
      s != RuntimeStatus::kOk)
    return s;
  texels_.assign(size_t(n) * n * 2, 0.0f);
  std::memcpy(texels_.data(), bytes.data(), texels_.size() * 4);
  for (float v : texels_)
    if (!std::isfinite(v) || std::fabs(v) > 1.0f) return RuntimeStatus::kInvalidAsset;
  levels_.assign(rec.levels, {});
  tile_mass_.assign(rec.levels, {});
  row_mass_.assign(rec.levels, {});
  const size_t image = size_t(res) * res;
  const bool half = (rec.flags & format::kTinyFlagHalf) != 0;
  for (uint32_t l = 0; l < rec.levels; ++l) {
    const uint64_t m = format::tinyTilesPerSide(rec.example_size, l);
    if (RuntimeStatus s =
            readSized(reader, half ? format::kSectionTinyExampleLevelHalf : format::kSectionTinyExampleLevel, l,
                      format::tinyLevelSectionSize(rec, l), &bytes);
        s != RuntimeStatus::kOk)
      return s;
    format::ImageSectionHeader h;
    if (half) {
      uint32_t head[5];
      std::memcpy(head, bytes.data(), sizeof head);
      h.width = head[1];
      h.height = head[2];
      h.channels = head[3];
      h.layers = head[4];
      if (head[0] != format::kTinyHalfImageMagic) return RuntimeStatus::kInvalidAsset;
    } else if (!format::parseImageSection(bytes.data(), bytes.size(), &h)) {
      return RuntimeStatus::kInvalidAsset;
    }
    if (h.width != rec.ndf_res || h.height != rec.ndf_res || h.channels != 1 || h.layers != m * m)
      return RuntimeStatus::kInvalidAsset;
    levels_[l].resize(size_t(m * m) * image);
    if (half) {
      for (size_t i = 0; i < levels_[l].size(); ++i) {
        uint16_t v;
        std::memcpy(&v, bytes.data() + 32 + 2 * i, 2);
        levels_[l][i] = format::halfToFloat(v);
      }
    } else {
      std::memcpy(levels_[l].data(), bytes.data() + 32, levels_[l].size() * 4);
    }
    for (float v : levels_[l])
      if (!(std::isfinite(v) && v >= 0.0f)) return RuntimeStatus::kInvalidAsset;
    tile_mass_[l].resize(size_t(m * m));
    row_mass_[l].resize(size_t(m * m) * res);
    for (size_t t = 0; t < m * m; ++t)
      tile_mass_[l][t] = rowIntegrals(levels_[l].data() + t * image, res, row_mass_[l].data() + t * res);
  }
  layout_ = format::TinyLayout();
  layout_values_.clear();
  if ((rec.flags & format::kTinyFlagLayout) != 0) {
    const int idx = reader.find(format::kSectionTinyExampleLayout, 0);
    if (idx < 0 || reader.sections()[size_t(idx)].raw_size < 32) return RuntimeStatus::kInvalidAsset;
    if (RuntimeStatus s = fromFormatStatus(reader.readSection(size_t(idx), &bytes)); s != RuntimeStatus::kOk) return s;
    format::ImageSectionHeader h;
    if (!format::parseImageSection(bytes.data(), bytes.size(), &h) || h.layers != 1 || h.width < 1 || h.height < 1 ||
        h.width > format::kMaxTinyLayoutSide || h.height > format::kMaxTinyLayoutSide || h.channels < 1 ||
        h.channels > format::kMaxTinyLayoutChannels ||
        bytes.size() != 32 + uint64_t(h.width) * h.height * h.channels * 4)
      return RuntimeStatus::kInvalidAsset;
    layout_values_.resize(size_t(h.width) * h.height * h.channels);
    std::memcpy(layout_values_.data(), bytes.data() + 32, layout_values_.size() * 4);
    layout_ = {h.width, h.height, h.channels, layout_values_.data()};
    if (format::checkTinyLayout(layout_)) return RuntimeStatus::kInvalidAsset;
  }
  std::vector<uint8_t>().swap(bytes);
  // The flat base of stochastic layouts: N(0, sigma_r^2 I), bin-integrated.
  base_.assign(image, 0.0f);
  base_rows_.assign(size_t(res), 0.0);
  const double bin = 2.0 / res;
  flakes::splatLobe({0.0, 0.0, rec.sigma_r * rec.sigma_r, 0.0, rec.sigma_r * rec.sigma_r}, 1.0 / (bin * bin), res,
                    base_.data());
  base_mass_ = rowIntegrals(base_.data(), res, base_rows_.data());
  record_ = rec;
  if (rec.type == uint32_t(TinyExampleType::kTiled) && TransformedExampleTexels::isGridTransform(rec.matrix)) {
    flake_texels_.reset(new (std::nothrow) TransformedExampleTexels(texels_.data(), n, true, rec.matrix));
    flakes_.reset(new (std::nothrow) FlakeNdf());
    if (!flake_texels_ || !flakes_) return RuntimeStatus::kOutOfMemory;
    if (RuntimeStatus s = flakes_->build(*flake_texels_, 1, rec.sigma_r, res); s != RuntimeStatus::kOk) return s;
  }
  open_ = true;
  return RuntimeStatus::kOk;
}

const float* TinyExampleNdf::tileImage(int level, int tile) const {
  if (!open_ || level < 0 || level >= int(levels_.size())) return nullptr;
  const size_t image = size_t(record_.ndf_res) * record_.ndf_res;
  if (tile < 0 || size_t(tile) >= levels_[size_t(level)].size() / image) return nullptr;
  return levels_[size_t(level)].data() + size_t(tile) * image;
}

FootprintRange TinyExampleNdf::footprintRange() const {
  FootprintRange r;
  if (!open_) return r;
  r.pyramid_min_sigma = 2.0;
  // Stochastic: the widest footprint whose window (and, with overlaps, the cells around it) stays
  // within kTinyMaxCells cells.
  const double side_cells = std::sqrt(double(kTinyMaxCells)) - 2.0 * format::tinyOverlapReach(record_) - 1.0;
  r.pyramid_max_sigma = record_.type == uint32_t(TinyExampleType::kTiled)
                            ? 1e300
                            : side_cells * record_.cell_size / (2.0 * kTinyWindowSigmas);
  r.exact_max_sigma = kTinyFlakesExactUpTo;
  r.handover_max_sigma = kTinyFlakesUpTo;
  return r;
}

MapSize TinyExampleNdf::mapSize() const {
  return open_ ? MapSize{int(record_.example_size), int(record_.example_size)} : MapSize{};
}

bool TinyExampleNdf::validFootprint(const Footprint& f) const {
  if (!(open_ && std::isfinite(f.x) && std::isfinite(f.y) && std::isfinite(f.sigma) && f.sigma >= 0.0)) return false;
  return std::fabs(f.x) <= 1e12 && std::fabs(f.y) <= 1e12;
}

// The flakes' share of a footprint's answer: 1 up to kTinyFlakesExactUpTo, 0 from kTinyFlakesUpTo on,
// linear in log(sigma) between (the tiles take the rest).
static double tinyFlakeShare(double sigma) {
  if (!(sigma > kTinyFlakesExactUpTo)) return 1.0;
  if (sigma >= kTinyFlakesUpTo) return 0.0;
  return std::log(kTinyFlakesUpTo / sigma) / std::log(kTinyFlakesUpTo / kTinyFlakesExactUpTo);
}

// The answer of the two paths, the flakes' share a of it (the tiles' value t unused when a >= 1).
static double blendPaths(double a, double f, double t) { return a >= 1.0 ? f : a * f + (1.0 - a) * t; }

// The footprint in the transformed example's grid (the flakes' coordinates).
Footprint TinyExampleNdf::flakeFootprint(const Footprint& f) const {
  return {f.x - record_.translate[0] - flake_texels_->offsetX(), f.y - record_.translate[1] - flake_texels_->offsetY(),
          f.sigma};
}

// ---------------------------------------------------------------------------------------------
// Traversal: visit(frame, image, rows, tile mass, weight) for every kept tile, the base last.

struct TinyExampleNdf::Visit {
  const Frame* frame;
  const float* image;
  const double* rows;
  double mass;
  double weight;
};

template <typename F>
bool TinyExampleNdf::traverse(const Footprint& fp, F&& visit, int64_t* entered) const {
  const TinyExampleRecord& r = record_;
  const double n = r.example_size;
  const int top = int(r.levels) - 1;
  const size_t image = size_t(r.ndf_res) * r.ndf_res;
  const int res = int(r.ndf_res);
  // Wider footprints of stochastic layouts are clamped (footprintRange).
  const double sigma = std::clamp(fp.sigma, kMinSigma, footprintRange().pyramid_max_sigma);
  // Overlapping layouts: the probability of the footprint on covered ground is the sum of the kept
  // tiles' (owned) weights.
  const bool overlap = format::tinyOverlapReach(r) > 0;
  double owned_weight = 0.0;
  auto emit = [&](const Visit& v) {
    if (overlap) owned_weight += v.weight;
    visit(v);
  };

  // Descends from the top tile of one example (example frame offset ox, oy; Gaussian g).
  auto descend = [&](const Frame& frame, const Gauss& g, double ox, double oy, auto&& self, int level, int ix,
                     int iy) -> void {
    const double t = double(2 << level);
    const double x0 = ox + ix * t, y0 = oy + iy * t;
    const double w = boxProbability(g, x0, x0 + t, y0, y0 + t);
    if (!(w > kNegligible)) return;
    if (level > 0) {
      const double dx = x0 + 0.5 * t - g.mx, dy = y0 + 0.5 * t - g.my;
      const double d = std::sqrt(dx * dx + dy * dy);
      if (w * t * (d + t) > kTinyRefine * g.lambda_min) {
        for (int c = 0; c < 4; ++c) self(frame, g, ox, oy, self, level - 1, 2 * ix + (c & 1), 2 * iy + (c >> 1));
        return;
      }
    }
    const int m = int(n) >> (level + 1);
    const size_t tile = size_t(iy) * size_t(m) + size_t(ix);
    emit(Visit{&frame, levels_[size_t(level)].data() + tile * image, row_mass_[size_t(level)].data() + tile * res,
               tile_mass_[size_t(level)][tile], w});
  };

  if (r.type == uint32_t(TinyExampleType::kTiled)) {
    const Frame frame = makeFrame(r.matrix);
    double inv[4];
    format::tinyInvert(r.matrix, inv);
    const double dx = fp.x - r.translate[0], dy = fp.y - r.translate[1];
    const double mx = inv[0] * dx + inv[1] * dy, my = inv[2] * dx + inv[3] * dy;
    double cov[4];
    const double inv_t[4] = {inv[0], inv[2], inv[1], inv[3]};
    mul(inv, inv_t, cov);
    const double s2 = sigma * sigma;
    const Gauss g = makeGauss(mx, my, s2 * cov[0], s2 * cov[1], s2 * cov[3]);
    if (g.lambda_min >= n * n) {
      // The periodic sum of a footprint this wide weighs every texel alike (within 1e-8): the top tile.
      if (entered) ++*entered;
      visit(Visit{&frame, levels_[size_t(top)].data(), row_mass_[size_t(top)].data(), tile_mass_[size_t(top)][0], 1.0});
      return true;
    }
    const double rx = kTinyWindowSigmas * g.sx, ry = kTinyWindowSigmas * g.sy;
    // Extreme transforms or positions (a damaged asset, a footprint far out) leave the int range:
    // not answered, as a window of too many cells.
    if (!windowInRange(mx, rx, n) || !windowInRange(my, ry, n)) return false;
    const int64_t cx0 = int64_t(std::floor((mx - rx) / n)), cx1 = int64_t(std::floor((mx + rx) / n));
    const int64_t cy0 = int64_t(std::floor((my - ry) / n)), cy1 = int64_t(std::floor((my + ry) / n));
    if (cx1 - cx0 >= kTinyMaxCopies || cy1 - cy0 >= kTinyMaxCopies ||
        (cx1 - cx0 + 1) * (cy1 - cy0 + 1) > kTinyMaxCopies)
      return false;
    for (int64_t cy = cy0; cy <= cy1; ++cy) {
      for (int64_t cx = cx0; cx <= cx1; ++cx) {
        if (entered) ++*entered;
        descend(frame, g, double(cx) * n, double(cy) * n, descend, top, 0, 0);
      }
    }
    return true;
  }

  // Stochastic: the cells of the window (overlapping layouts: and the cells whose examples reach
  // into it), each example in its own frame, then the flat base.
  const double cell = r.cell_size;
  const double reach = kTinyWindowSigmas * sigma;
  const int cells_out = format::tinyOverlapReach(r);
  if (!windowInRange(fp.x, reach, cell) || !windowInRange(fp.y, reach, cell)) return false;
  const int64_t i0 = int64_t(std::floor((fp.x - reach) / cell)) - cells_out,
                i1 = int64_t(std::floor((fp.x + reach) / cell)) + cells_out;
  const int64_t j0 = int64_t(std::floor((fp.y - reach) / cell)) - cells_out,
                j1 = int64_t(std::floor((fp.y + reach) / cell)) + cells_out;
  if (i1 - i0 >= kTinyMaxCells || j1 - j0 >= kTinyMaxCells || (i1 - i0 + 1) * (j1 - j0 + 1) > kTinyMaxCells)
    return false;
  double covered = 0.0;
  // Built only for overlapping layouts (it is large: no cost for the others).
  std::optional<PlacementCache> cache;
  if (overlap) {
    cache.emplace();
    cache->record = &r;
    cache->layout = layout();
    cache->begin(i0 - 2 * cells_out, i1 + 2 * cells_out, 2 * cells_out);
  }
  for (int64_t j = j0; j <= j1; ++j) {
    if (overlap) cache->walkTo(j);
    for (int64_t i = i0; i <= i1; ++i) {
      const format::TinyPlacement p = overlap ? cache->at(i, j) : format::tinyCellPlacement(r, i, j, layout());
      if (!p.present) continue;
      double inv[4];
      if (!format::tinyInvert(p.matrix, inv)) continue;
      const double dx = fp.x - p.centre[0], dy = fp.y - p.centre[1];
      const double mx = inv[0] * dx + inv[1] * dy + 0.5 * n, my = inv[2] * dx + inv[3] * dy + 0.5 * n;
      double cov[4];
      const double inv_t[4] = {inv[0], inv[2], inv[1], inv[3]};
      mul(inv, inv_t, cov);
      const double s2 = sigma * sigma;
      const Gauss g = makeGauss(mx, my, s2 * cov[0], s2 * cov[1], s2 * cov[3]);
      if (mx + kTinyWindowSigmas * g.sx < 0.0 || mx - kTinyWindowSigmas * g.sx > n ||
          my + kTinyWindowSigmas * g.sy < 0.0 || my - kTinyWindowSigmas * g.sy > n)
        continue;
      const Frame frame = makeFrame(p.matrix);
      if (entered) ++*entered;
      if (!overlap) {
        covered += boxProbability(g, 0.0, n, 0.0, n);
        descend(frame, g, 0.0, 0.0, descend, top, 0, 0);
        continue;
      }
      OwnedExample e;
      if (!gatherNeighbours(r, *cache, p, cells_out, &e)) {
        descend(frame, g, 0.0, 0.0, descend, top, 0, 0);
        continue;
      }
      // Tiles wholly owned descend as without overlaps; tiles others take wholly are dropped; tiles
      // on the boundary are split while the rule asks, then kept with the owned share of their weight.
      auto owned = [&](int level, int ix, int iy, auto&& self) -> void {
        const double t = double(2 << level);
        const double x0 = ix * t, y0 = iy * t;
        const double w = boxProbability(g, x0, x0 + t, y0, y0 + t);
        if (!(w > kNegligible)) return;
        const Ownership own = classifyTile(r, e, x0, y0, t);
        if (own == Ownership::kNone) return;
        if (own == Ownership::kFull) {
          descend(frame, g, 0.0, 0.0, descend, level, ix, iy);
          return;
        }
        const double ox = x0 + 0.5 * t - g.mx, oy = y0 + 0.5 * t - g.my;
        if (level > 0 && w * t * (std::sqrt(ox * ox + oy * oy) + t) > kTinyRefine * g.lambda_min) {
          for (int c = 0; c < 4; ++c) self(level - 1, 2 * ix + (c & 1), 2 * iy + (c >> 1), self);
          return;
        }
        const double share = ownedShare(r, e, g, x0, y0, t, level > 0 ? 8 : 4);
        if (!(share > 0.0)) return;
        const int m = int(n) >> (level + 1);
        const size_t tile = size_t(iy) * size_t(m) + size_t(ix);
        emit(Visit{&frame, levels_[size_t(level)].data() + tile * image, row_mass_[size_t(level)].data() + tile * res,
                   tile_mass_[size_t(level)][tile], w * share});
      };
      owned(top, 0, 0, owned);
    }
  }
  if (overlap) covered = owned_weight;
  const double rest = 1.0 - covered;
  if (rest > kNegligible) {
    static const Frame base_frame = makeFrame(kIdentity);
    visit(Visit{&base_frame, base_.data(), base_rows_.data(), base_mass_, rest});
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Queries.

RuntimeStatus TinyExampleNdf::traversalCount(const Footprint& fp, int64_t* examples, int64_t* tiles) const {
  if (!validFootprint(fp) || !examples || !tiles) return RuntimeStatus::kInvalidArgument;
  int64_t e = 0, t = 0;
  if (!traverse(
          fp, [&](const Visit&) { ++t; }, &e))
    return RuntimeStatus::kInvalidArgument;
  *examples = e;
  *tiles = t;
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::tileEval(const Footprint& fp, const SPoint& s, double* value) const {
  if (!inSquare(s)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  const int res = int(record_.ndf_res);
  double sum = 0.0;
  if (!traverse(fp, [&](const Visit& v) {
        const Frame& f = *v.frame;
        const double ex = f.b[0] * s.x + f.b[1] * s.y, ey = f.b[2] * s.x + f.b[3] * s.y;
        if (!(ex >= -1.0 && ex <= 1.0 && ey >= -1.0 && ey <= 1.0)) return;
        sum += v.weight * f.jac * double(v.image[size_t(binRow(ey, res)) * res + size_t(binColumn(ex, res))]);
      }))
    return RuntimeStatus::kInvalidArgument;
  *value = sum;
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::tileMass(const Footprint& fp, double* value) const {
  double sum = 0.0;
  if (!traverse(fp, [&](const Visit& v) { sum += v.weight * v.mass; })) return RuntimeStatus::kInvalidArgument;
  *value = sum;
  return RuntimeStatus::kOk;
}

namespace {

Poly transformedRect(const double b[4], double x0, double x1, double y0, double y1) {
  Poly p;
  const double xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
  for (int k = 0; k < 4; ++k) {
    p.x[k] = b[0] * xs[k] + b[1] * ys[k];
    p.y[k] = b[2] * xs[k] + b[3] * ys[k];
  }
  p.n = 4;
  return p;
}

bool sameFrame(const TinyExampleNdf::Frame& a, const TinyExampleNdf::Frame& b) {
  return std::memcmp(a.b, b.b, sizeof a.b) == 0;
}

}  // namespace

// Tiles of one frame gathered so that the transformed rectangles are clipped once for all of them.
struct TinyExampleNdf::Batch {
  static constexpr int kCapacity = 256;
  Frame frame;
  bool has_frame = false;
  WeightedImage images[kCapacity];
  int count = 0;
};

template <typename F>
bool TinyExampleNdf::batched(const Footprint& fp, F&& flush) const {
  Batch batch;
  auto emit = [&]() {
    if (batch.count > 0) flush(static_cast<const Batch&>(batch));
    batch.count = 0;
  };
  if (!traverse(fp, [&](const Visit& v) {
        if (!batch.has_frame || !sameFrame(batch.frame, *v.frame) || batch.count == Batch::kCapacity) {
          emit();
          batch.frame = *v.frame;
          batch.has_frame = true;
        }
        batch.images[batch.count++] = {v.image, v.weight};
      }))
    return false;
  emit();
  return true;
}

RuntimeStatus TinyExampleNdf::tileAverage(const Footprint& fp, const SRect& rect, double* value) const {
  const double x0 = std::max(rect.x0, -1.0), x1 = std::min(rect.x1, 1.0);
  const double y0 = std::max(rect.y0, -1.0), y1 = std::min(rect.y1, 1.0);
  const double out_area = (rect.x1 - rect.x0) * (rect.y1 - rect.y0);
  if (!(x1 > x0 && y1 > y0)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  const int res = int(record_.ndf_res);
  double integral = 0.0;
  if (!batched(fp, [&](const Batch& batch) {
        integral += polygonIntegral(transformedRect(batch.frame.b, x0, x1, y0, y1), batch.images, batch.count, res);
      }))
    return RuntimeStatus::kInvalidArgument;
  *value = integral / out_area;
  return RuntimeStatus::kOk;
}

// Adds weight times the tiles' image to out (R * R floats).
RuntimeStatus TinyExampleNdf::addTileImage(const Footprint& fp, double weight, float* out) const {
  const int res = resolution();
  const double bin = 2.0 / res;
  if (!batched(fp, [&](const Batch& batch) {
        const Frame& f = batch.frame;
        for (int j = 0; j < res; ++j) {
          for (int i = 0; i < res; ++i) {
            if (!flakes::binInDisk(i, j, res)) continue;
            const double cx = -1.0 + (i + 0.5) * bin, cy = 1.0 - (j + 0.5) * bin;
            double v = 0.0;
            if (f.grid) {
              // A signed permutation maps the bin onto one stored bin.
              const double ex = f.b[0] * cx + f.b[1] * cy, ey = f.b[2] * cx + f.b[3] * cy;
              const size_t at = size_t(binRow(ey, res)) * res + size_t(binColumn(ex, res));
              for (int k = 0; k < batch.count; ++k) v += batch.images[k].weight * double(batch.images[k].image[at]);
            } else {
              v = polygonIntegral(transformedRect(f.b, cx - 0.5 * bin, cx + 0.5 * bin, cy - 0.5 * bin, cy + 0.5 * bin),
                                  batch.images, batch.count, res) /
                  (bin * bin);
            }
            out[size_t(j) * res + i] += float(weight * v);
          }
        }
      }))
    return RuntimeStatus::kInvalidArgument;
  return RuntimeStatus::kOk;
}

// Draws from the tiles' answer; the point only (the caller sets the pdf).
RuntimeStatus TinyExampleNdf::tileSample(const Footprint& fp, double total, double u1, double u2,
                                         NdfSample* out) const {
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
  // The tile, in proportion to weight x mass, in the traversal's order.
  double target = u1 * total, acc = 0.0;
  bool found = false;
  Frame frame;
  Visit chosen{};
  traverse(fp, [&](const Visit& v) {
    if (found) return;
    const double p = v.weight * v.mass;
    if (p <= 0.0) return;
    chosen = v;
    frame = *v.frame;  // the visit's frame lives only during the call
    if (target < acc + p) {
      found = true;
      return;
    }
    acc += p;
  });
  if (!chosen.image) return RuntimeStatus::kInvalidArgument;
  if (!found) acc -= chosen.weight * chosen.mass;  // rounding left the target at the end: the last tile
  const int res = int(record_.ndf_res);
  const double bin = 2.0 / res;
  double u = std::clamp((target - acc) / (chosen.weight * chosen.mass), 0.0, 0.99999999999999989);
  // A row by its integral, then a bin of the row; the uniform is rescaled and reused.
  double row_target = u * chosen.mass;
  int j = 0;
  for (; j < res - 1; ++j) {
    if (row_target < chosen.rows[j]) break;
    row_target -= chosen.rows[j];
  }
  while (j > 0 && chosen.rows[j] <= 0.0) --j;
  const double row = chosen.rows[j];
  double col_target = row > 0.0 ? std::clamp(row_target / row, 0.0, 0.99999999999999989) : 0.5;
  const float* line = chosen.image + size_t(j) * res;
  double line_sum = 0.0;
  for (int i = 0; i < res; ++i) line_sum += double(line[i]);
  col_target *= line_sum;
  int i = 0;
  for (; i < res - 1; ++i) {
    if (col_target < double(line[i])) break;
    col_target -= double(line[i]);
  }
  while (i > 0 && line[i] <= 0.0f) --i;
  const double rest = line[i] > 0.0f ? std::clamp(col_target / double(line[i]), 0.0, 0.99999999999999989) : 0.5;
  const double ex = -1.0 + (i + u2) * bin, ey = 1.0 - (j + rest) * bin;
  out->s.x = frame.a[0] * ex + frame.a[1] * ey;
  out->s.y = frame.a[2] * ex + frame.a[3] * ey;
  out->pdf = 0.0;
  return RuntimeStatus::kOk;
}

// ---------------------------------------------------------------------------------------------
// Small footprints: the flakes of the plane as the asset lays it (TinyPlaneTexels).

namespace {

// Texels per side of the largest window the plane flakes read: flakes within
// 6 sqrt(sigma_h^2 + sigma^2) of the centre for sigma < kTinyFlakesUpTo, and one texel on each side
// for the central differences.
constexpr int kPlaneWindow = 2 * int(6.0 * kTinyFlakesUpTo + 2.0) + 4;

struct PlaneWindow {
  int64_t x0 = 0, y0 = 0;  // plane texel of entry (0, 0)
  int w = 0, h = 0;
  float t[kPlaneWindow * kPlaneWindow * 2];
  const float* at(int64_t x, int64_t y) const { return t + (size_t(y - y0) * size_t(w) + size_t(x - x0)) * 2; }
};

}  // namespace

// Calls lobe(weight, Lobe) for every flake of the plane within the footprint's window: flake k at
// plane texel centre u_k = (X + 1/2, Y + 1/2) has the materialised texel's normal n_k and the central
// differences J_k of its neighbours (formats/SPEC.md 10.5 at rate 1), weight N(u_k; u, (sigma_h^2 +
// sigma^2) I) and lobe N(n_k + J_k c (u - u_k), sigma_r^2 I + sigma^2 c J_k J_k^T), c = sigma_h^2 /
// (sigma_h^2 + sigma^2). False when the window does not fit (not reached for sigma < kTinyFlakesUpTo).
template <typename F>
bool TinyExampleNdf::planeFlakes(const Footprint& fp, F&& lobe) const {
  const double sp2 = fp.sigma * fp.sigma, h2 = kSigmaH * kSigmaH, v = h2 + sp2;
  const double reach = 6.0 * std::sqrt(v);
  const int64_t fx0 = int64_t(std::ceil(fp.x - reach - 0.5)), fx1 = int64_t(std::floor(fp.x + reach - 0.5));
  const int64_t fy0 = int64_t(std::ceil(fp.y - reach - 0.5)), fy1 = int64_t(std::floor(fp.y + reach - 0.5));
  if (fx1 < fx0 || fy1 < fy0) return true;
  PlaneWindow win;
  win.x0 = fx0 - 1;
  win.y0 = fy0 - 1;
  win.w = int(fx1 - fx0 + 3);
  win.h = int(fy1 - fy0 + 3);
  if (win.w > kPlaneWindow || win.h > kPlaneWindow) return false;
  const TinyPlaneTexels plane(*this, win.x0, win.y0, win.w, win.h);
  for (int y = 0; y < win.h; ++y)
    for (int x = 0; x < win.w; ++x) plane.texel(x, y, win.t + (size_t(y) * win.w + x) * 2);
  const double c = h2 / v, spread = sp2 * c, r2 = record_.sigma_r * record_.sigma_r;
  const double norm = 1.0 / (kTwoPi * v);
  for (int64_t y = fy0; y <= fy1; ++y) {
    const double dy = fp.y - (double(y) + 0.5);
    for (int64_t x = fx0; x <= fx1; ++x) {
      const double dx = fp.x - (double(x) + 0.5);
      const double w = norm * std::exp(-0.5 * (dx * dx + dy * dy) / v);
      const float* nk = win.at(x, y);
      const float *l = win.at(x - 1, y), *r = win.at(x + 1, y), *u = win.at(x, y - 1), *d = win.at(x, y + 1);
      // As the flake model stores them: float normals and Jacobians.
      const double j0 = double(float((double(r[0]) - double(l[0])) * 0.5)),
                   j1 = double(float((double(d[0]) - double(u[0])) * 0.5));
      const double j2 = double(float((double(r[1]) - double(l[1])) * 0.5)),
                   j3 = double(float((double(d[1]) - double(u[1])) * 0.5));
      const flakes::Lobe g{double(nk[0]) + c * (j0 * dx + j1 * dy), double(nk[1]) + c * (j2 * dx + j3 * dy),
                           r2 + spread * (j0 * j0 + j1 * j1), spread * (j0 * j2 + j1 * j3),
                           r2 + spread * (j2 * j2 + j3 * j3)};
      lobe(w, g);
    }
  }
  return true;
}

namespace {

double lobeDensity(const flakes::Lobe& g, double sx, double sy) {
  const double det = g.cxx * g.cyy - g.cxy * g.cxy;
  const double dx = sx - g.mx, dy = sy - g.my;
  const double q = (g.cyy * dx * dx - 2.0 * g.cxy * dx * dy + g.cxx * dy * dy) / det;
  return std::exp(-0.5 * q) / (kTwoPi * std::sqrt(det));
}

}  // namespace

// The flakes' answers: the grid-preserving tiled transforms through FlakeNdf over the transformed
// example, every other asset through the plane flakes above (the same model and texels).
RuntimeStatus TinyExampleNdf::flakeEval(const Footprint& fp, const SPoint& s, double* value) const {
  if (hasGridFlakes()) return flakes_->eval(flakeFootprint(fp), s, value);
  double sum = 0.0;
  if (inSquare(s) && !planeFlakes(fp, [&](double w, const flakes::Lobe& g) { sum += w * lobeDensity(g, s.x, s.y); }))
    return RuntimeStatus::kInvalidArgument;
  *value = sum;
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::flakeMass(const Footprint& fp, double* value) const {
  if (hasGridFlakes()) return flakes_->mass(flakeFootprint(fp), value);
  double sum = 0.0;
  if (!planeFlakes(fp, [&](double w, const flakes::Lobe&) { sum += w; })) return RuntimeStatus::kInvalidArgument;
  *value = sum;
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::flakeAverage(const Footprint& fp, const SRect& rect, double* value) const {
  if (hasGridFlakes()) return flakes_->average(flakeFootprint(fp), rect, value);
  const double x0 = std::max(rect.x0, -1.0), x1 = std::min(rect.x1, 1.0);
  const double y0 = std::max(rect.y0, -1.0), y1 = std::min(rect.y1, 1.0);
  double sum = 0.0;
  if (x1 > x0 && y1 > y0 && !planeFlakes(fp, [&](double w, const flakes::Lobe& g) {
        sum += w * flakes::lobeRectProbability(g, x0, x1, y0, y1);
      }))
    return RuntimeStatus::kInvalidArgument;
  *value = sum / ((rect.x1 - rect.x0) * (rect.y1 - rect.y0));
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::addFlakeImage(const Footprint& fp, double weight, float* out) const {
  const int res = resolution();
  if (hasGridFlakes()) return flakes_->addImage(flakeFootprint(fp), weight, out, size_t(res) * res);
  const double bin = 2.0 / res;
  if (!planeFlakes(fp,
                   [&](double w, const flakes::Lobe& g) { flakes::splatLobe(g, weight * w / (bin * bin), res, out); }))
    return RuntimeStatus::kInvalidArgument;
  return RuntimeStatus::kOk;
}

// Draws from the flakes' answer; the point only (the caller sets the pdf).
RuntimeStatus TinyExampleNdf::flakeSample(const Footprint& fp, double total, double u1, double u2,
                                          NdfSample* out) const {
  if (hasGridFlakes()) return flakes_->sample(flakeFootprint(fp), u1, u2, out);
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
  // The flake in proportion to its weight, in the window's order, then a point of its lobe (Box-Muller
  // on the rescaled u1 and u2).
  const double target = u1 * total;
  double acc = 0.0, rest = 0.5;
  bool found = false;
  flakes::Lobe chosen{0.0, 0.0, 1.0, 0.0, 1.0};
  planeFlakes(fp, [&](double w, const flakes::Lobe& g) {
    if (found || !(w > 0.0)) return;
    chosen = g;
    if (target < acc + w) {
      found = true;
      rest = (target - acc) / w;
      return;
    }
    acc += w;
  });
  rest = std::clamp(rest, 0.0, 0.99999999999999989);
  const double radius = std::sqrt(-2.0 * std::log1p(-rest)), phi = kTwoPi * u2;
  const double z0 = radius * std::cos(phi), z1 = radius * std::sin(phi);
  const double l00 = std::sqrt(chosen.cxx), l10 = chosen.cxy / l00;
  const double l11 = std::sqrt(std::max(chosen.cyy - l10 * l10, 0.0));
  out->s.x = chosen.mx + l00 * z0;
  out->s.y = chosen.my + l10 * z0 + l11 * z1;
  out->pdf = 0.0;
  return RuntimeStatus::kOk;
}

// ---------------------------------------------------------------------------------------------
// The queries: the flakes below kTinyFlakesExactUpTo, the tiles from kTinyFlakesUpTo, blended
// linearly in log(sigma) between.

RuntimeStatus TinyExampleNdf::eval(const Footprint& fp, const SPoint& s, double* value) const {
  if (!value || !validFootprint(fp) || !finitePoint(s)) return RuntimeStatus::kInvalidArgument;
  const double a = tinyFlakeShare(fp.sigma);
  double f = 0.0, t = 0.0;
  if (a > 0.0)
    if (RuntimeStatus st = flakeEval(fp, s, &f); st != RuntimeStatus::kOk) return st;
  if (a < 1.0)
    if (RuntimeStatus st = tileEval(fp, s, &t); st != RuntimeStatus::kOk) return st;
  *value = blendPaths(a, f, t);
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::mass(const Footprint& fp, double* value) const {
  if (!value || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  const double a = tinyFlakeShare(fp.sigma);
  double f = 0.0, t = 0.0;
  if (a > 0.0)
    if (RuntimeStatus st = flakeMass(fp, &f); st != RuntimeStatus::kOk) return st;
  if (a < 1.0)
    if (RuntimeStatus st = tileMass(fp, &t); st != RuntimeStatus::kOk) return st;
  *value = blendPaths(a, f, t);
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::pdf(const Footprint& fp, const SPoint& s, double* value) const {
  if (!value || !validFootprint(fp) || !finitePoint(s)) return RuntimeStatus::kInvalidArgument;
  double e = 0.0, m = 0.0;
  if (RuntimeStatus st = eval(fp, s, &e); st != RuntimeStatus::kOk) return st;
  if (RuntimeStatus st = mass(fp, &m); st != RuntimeStatus::kOk) return st;
  *value = m > 0.0 ? e / m : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::average(const Footprint& fp, const SRect& rect, double* value) const {
  if (!value || !validFootprint(fp) || !validRect(rect)) return RuntimeStatus::kInvalidArgument;
  const double a = tinyFlakeShare(fp.sigma);
  double f = 0.0, t = 0.0;
  if (a > 0.0)
    if (RuntimeStatus st = flakeAverage(fp, rect, &f); st != RuntimeStatus::kOk) return st;
  if (a < 1.0)
    if (RuntimeStatus st = tileAverage(fp, rect, &t); st != RuntimeStatus::kOk) return st;
  *value = blendPaths(a, f, t);
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::image(const Footprint& fp, float* out, size_t out_count) const {
  const int res = resolution();
  const size_t count = size_t(res) * size_t(res);
  if (!out || count == 0 || out_count < count || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  if (hasGridFlakes() && tinyFlakeShare(fp.sigma) >= 1.0) return flakes_->image(flakeFootprint(fp), out, out_count);
  std::fill(out, out + count, 0.0f);
  const double a = tinyFlakeShare(fp.sigma);
  if (a > 0.0)
    if (RuntimeStatus st = addFlakeImage(fp, a, out); st != RuntimeStatus::kOk) return st;
  if (a < 1.0)
    if (RuntimeStatus st = addTileImage(fp, 1.0 - a, out); st != RuntimeStatus::kOk) return st;
  return RuntimeStatus::kOk;
}

RuntimeStatus TinyExampleNdf::sample(const Footprint& fp, double u1, double u2, NdfSample* out) const {
  if (!out || !validFootprint(fp) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  // The path in proportion to its share of the mass, u1 rescaled for the chosen one.
  const double a = tinyFlakeShare(fp.sigma);
  double mf = 0.0, mt = 0.0;
  if (a > 0.0)
    if (RuntimeStatus st = flakeMass(fp, &mf); st != RuntimeStatus::kOk) return st;
  if (a < 1.0)
    if (RuntimeStatus st = tileMass(fp, &mt); st != RuntimeStatus::kOk) return st;
  const double pf = a * mf, pt = (1.0 - a) * mt;
  if (!(pf + pt > 0.0)) return RuntimeStatus::kInvalidArgument;
  const double split = pf / (pf + pt);
  RuntimeStatus st;
  if (u1 < split || !(pt > 0.0)) {
    st = flakeSample(fp, mf, std::clamp(u1 / split, 0.0, 0.99999999999999989), u2, out);
  } else {
    st = tileSample(fp, mt, std::clamp((u1 - split) / (1.0 - split), 0.0, 0.99999999999999989), u2, out);
  }
  if (st != RuntimeStatus::kOk) return st;
  if (!inSquare(out->s)) {
    out->pdf = 0.0;
    return RuntimeStatus::kOk;
  }
  // pdf() with the masses above (the same sums: the same bits).
  double e = 0.0;
  if (RuntimeStatus est = eval(fp, out->s, &e); est != RuntimeStatus::kOk) return est;
  const double m = blendPaths(a, mf, mt);
  out->pdf = m > 0.0 ? e / m : 0.0;
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
