// SPDX-License-Identifier: Apache-2.0
// Queries of tensor-ndf assets: the NdfPyramid blend over centres and levels, reduced per block to
// a CpMix (cp_block.h) of its (group, row, weight) terms.
#include "tensor_ndf_impl.h"

#include "../pyramid_blend.h"
#include "lane_sum.h"

#include <algorithm>
#include <cmath>

namespace glintbake::runtime {
namespace {

constexpr double kOneMinusEpsilon = 0x1.fffffffffffffp-1;

// s-plane density of a bin from the block's share of the blend's mass and the within-block pdf
// (per unit bin area). sample() and pdf() both form it here, so they agree bit for bit.
double combinePdf(double block_mass, double total_mass, double bin_pdf, double bin_area) {
  return (block_mass / total_mass) * bin_pdf / bin_area;
}

// The integral of a factor column between x0 and x1 (0 <= x0 <= x1 <= B, bin units) is
//   P[k1] + f1 F[k1] - P[k0] - f0 F[k0]     (k = floor(x), f = x - k; P the prefix sums),
// or (x1 - x0) F[k0] when both ends lie in one bin (no prefix-sum cancellation there). Float, as
// stored: the rounding of the stored prefix sums bounds the accuracy whatever the arithmetic.
struct Span {
  int32_t k0, k1;
  float f0, f1;
  bool single;
  Span(double x0, double x1, int32_t bins) {
    k0 = std::min(int32_t(x0), bins - 1);
    k1 = std::min(int32_t(x1), bins - 1);
    f0 = float(x0 - k0);
    f1 = float(x1 - k1);
    single = k0 == k1;
  }
  // The integral of column r alone.
  float column(const float* factor, const float* prefix, int32_t rank, int32_t r) const {
    const float a0 = factor[size_t(k0) * size_t(rank) + size_t(r)];
    if (single) return (f1 - f0) * a0;
    const float a1 = factor[size_t(k1) * size_t(rank) + size_t(r)];
    const float p0 = prefix[size_t(k0) * size_t(rank) + size_t(r)];
    const float p1 = prefix[size_t(k1) * size_t(rank) + size_t(r)];
    return ((p1 - p0) + f1 * a1) - f0 * a0;
  }
  // The integrals of all `rank` columns, into out[0, rank).
  void extents(const float* factor, const float* prefix, int32_t rank, float* out) const {
    const float* a0 = factor + size_t(k0) * size_t(rank);
    if (single) {
      const float w = f1 - f0;
      for (int32_t r = 0; r < rank; ++r) out[r] = w * a0[r];
      return;
    }
    const float* a1 = factor + size_t(k1) * size_t(rank);
    const float* p0 = prefix + size_t(k0) * size_t(rank);
    const float* p1 = prefix + size_t(k1) * size_t(rank);
    for (int32_t r = 0; r < rank; ++r) out[r] = ((p1[r] - p0[r]) + f1 * a1[r]) - f0 * a0[r];
  }
};

}  // namespace

int TensorNdf::Impl::binOf(double sx, double sy) const { return ndfBinOf(sx, sy, res, inv_bin); }

void TensorNdf::Impl::blend(const Footprint& fp, Blend* b) const {
  b->count = 0;
  blender.blend(fp.x, fp.y, fp.sigma, [&](int level, size_t centre, double weight) {
    const TLevel& lv = levels[level];
    const size_t first = centre * size_t(nb2);
    b->weight[b->count] = weight;
    b->index[b->count] = lv.index.data + first;
    b->mass[b->count] = lv.mass.data + first;
    ++b->count;
  });
}

static_assert(kCpMaxBlend >= format::kMaxBlendCentres, "a CpMix holds every centre of a footprint blend");

void TensorNdf::Impl::mixBlock(const Blend& b, uint64_t block, CpMix* mix) const {
  CpBlendTerm terms[kCpMaxBlend];
  int n = 0;
  for (int t = 0; t < b.count; ++t) {
    const TensorIndexEntry& e = b.index[t][block];
    if (e.group == kTensorBlankGroup) continue;
    // The loader's raw masses are in s-plane units (bin area times the bins' sum).
    terms[n++] = CpBlendTerm{&groups.data[e.group].view, int32_t(e.row), float(b.weight[t]),
                             float(b.mass[t][block] * inv_bin_area)};
  }
  // Entries were validated at load: init cannot fail.
  mix->init(terms, n);
}

double TensorNdf::Impl::blockRangeIntegral(const Blend& b, uint64_t block, double x0, double x1, double y0,
                                           double y1) const {
  // Rank-1 terms are separable: per group, the R column integrals over x and over y; per term,
  // their triple product with its C row. Terms of one group are usually adjacent in the blend, so
  // the integrals are formed once per run of equal groups.
  const Span sx(x0, x1, bins), sy(y0, y1, bins);
  const CpGroupView* current = nullptr;
  float ex[kCpMaxRank], ey[kCpMaxRank];
  Dot3Lanes lanes;
  float exact = 0.0f;  // the exact blocks' terms (as binValue)
  for (int t = 0; t < b.count; ++t) {
    const TensorIndexEntry& e = b.index[t][block];
    if (e.group == kTensorBlankGroup || b.weight[t] == 0.0) continue;
    const CpGroupView* v = &groups.data[e.group].view;
    const int32_t rank = v->rank;
    if (v->identity_a) {
      // An exact block: column r of A is the indicator of bin r, so only the columns the range
      // covers contribute, each its partial width times its integral down the rows.
      const float* crow = v->c + size_t(e.row) * size_t(rank);
      float sum = 0.0f;
      for (int32_t r = sx.k0; r <= sx.k1; ++r) {
        const float wx = sx.single ? sx.f1 - sx.f0 : (r == sx.k0 ? 1.0f - sx.f0 : (r == sx.k1 ? sx.f1 : 1.0f));
        if (!(wx > 0.0f)) continue;
        sum += wx * crow[r] * sy.column(v->b, v->b_prefix, rank, r);
      }
      exact += float(b.weight[t]) * sum;
      continue;
    }
    if (v != current) {
      sx.extents(v->a, v->a_prefix, rank, ex);
      sy.extents(v->b, v->b_prefix, rank, ey);
      current = v;
    }
    lanes.add(ex, ey, v->c + size_t(e.row) * size_t(rank), rank, float(b.weight[t]));
  }
  return double(lanes.total() + exact);
}

double TensorNdf::Impl::blockMass(const Blend& b, uint64_t block) const {
  double m = 0.0;
  for (int t = 0; t < b.count; ++t) m += b.weight[t] * b.mass[t][block];
  return m > 0.0 ? m : 0.0;
}

double TensorNdf::Impl::totalMass(const Blend& b, double* masses) const {
  if (!keepsMasses()) {
    double total = 0.0;
    for (uint64_t k = 0; k < nb2; ++k) total += blockMass(b, k);
    return total;
  }
  // Centre by centre over every block (each centre's masses are contiguous): every block's sum
  // adds its terms in blockMass's order, so the same bits.
  double acc[kMassBlocks];
  std::fill(acc, acc + nb2, 0.0);
  for (int t = 0; t < b.count; ++t) {
    const double w = b.weight[t];
    const double* m = b.mass[t];
    for (uint64_t k = 0; k < nb2; ++k) acc[k] += w * m[k];
  }
  double total = 0.0;
  for (uint64_t k = 0; k < nb2; ++k) {
    const double mk = acc[k] > 0.0 ? acc[k] : 0.0;
    if (masses) masses[k] = mk;
    total += mk;
  }
  return total;
}

double TensorNdf::Impl::mixtureMass(const format::NdfBlendLevel* parts, int count, double* rows) const {
  double total = 0.0;
  int r = 0;
  for (int p = 0; p < count; ++p) {
    const format::NdfBlendLevel& part = parts[p];
    const double* centre_mass = levels[part.level].centre_mass.data;
    for (int b = 0; b < part.ny; ++b) {
      double row = 0.0;
      part.forEachInRow(b, [&](int a, double w) { row += w * centre_mass[part.centre(a, b)]; });
      if (rows) rows[r] = row;
      ++r;
      total += row;
    }
  }
  return total;
}

double TensorNdf::Impl::pointValue(const format::NdfBlendLevel* parts, int count, uint64_t block, int bi,
                                   int bj) const {
  // sum_c w_c v_c over the blend's centres, v_c the centre's model value at the bin: one load of a
  // dense level's values (the centres of a bin side by side), else the triple product of the
  // centre's C row with its group's A and B rows (an exact block: one product).
  double sum = 0.0;
  for (int p = 0; p < count; ++p) {
    const format::NdfBlendLevel& part = parts[p];
    const PointLevel& pl = point[part.level];
    if (pl.dense) {
      const uint64_t cell = (block * uint64_t(bins) + uint64_t(bj)) * uint64_t(bins) + uint64_t(bi);
      const float* v = pl.values.data + cell * pl.centres;
      part.forEachWeight([&](int a, int b, double w) { sum += w * double(v[part.centre(a, b)]); });
      continue;
    }
    const PointSlot* slots = pl.slots.data + block * pl.centres;
    part.forEachWeight([&](int a, int b, double w) {
      const PointSlot& slot = slots[part.centre(a, b)];
      if (slot.group == kTensorBlankGroup) return;
      const CpGroupView& v = groups.data[slot.group].view;
      const float* row = pl.rows.data + uint64_t(slot.row) * uint64_t(pl.row_stride);
      const size_t rank = size_t(v.rank);
      const float value = v.identity_a ? row[bi] * v.b[size_t(bj) * rank + size_t(bi)]
                                       : laneDot3(v.a + size_t(bi) * rank, v.b + size_t(bj) * rank, row, v.rank);
      sum += w * double(value);
    });
  }
  return sum > 0.0 ? sum : 0.0;
}

double TensorNdf::Impl::imagePointValue(const format::NdfBlendLevel* parts, int count, int i, int j) const {
  int bx, by, bi, bj;
  splitBin(i, &bx, &bi);
  splitBin(j, &by, &bj);
  return pointValue(parts, count, uint64_t(by) * uint64_t(nb) + uint64_t(bx), bi, bj);
}

double TensorNdf::Impl::binPdf(const Blend& b, int i, int j) const {
  double masses[kMassBlocks];
  const double total = totalMass(b, masses);
  if (!(total > 0.0)) return 0.0;
  const uint64_t block = uint64_t(j / bins) * uint64_t(nb) + uint64_t(i / bins);
  const double m = keepsMasses() ? masses[block] : blockMass(b, block);
  if (!(m > 0.0)) return 0.0;
  CpMix mix;
  mixBlock(b, block, &mix);
  // A block whose blended raw mass is positive but whose float range sum rounds to <= 0 is
  // sampled uniformly (sample() does the same).
  const double p = mix.blockMass() > 0.0f ? mix.pdf(i % bins, j % bins) : 1.0 / (double(bins) * bins);
  return combinePdf(m, total, p, bin_area);
}

// ---------------------------------------------------------------------------------------------

RuntimeStatus TensorNdf::evalChecked(const Footprint& footprint, const SPoint& s, double* value) const {
  const Impl& m = *impl_;
  int i, j;
  if (!ndfBinCoords(s.x, s.y, m.res, m.inv_bin, &i, &j)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  format::NdfBlendLevel parts[2];
  const int n = m.blender.levels(footprint.x, footprint.y, footprint.sigma, parts);
  *value = m.imagePointValue(parts, n, i, j);
  return RuntimeStatus::kOk;
}

RuntimeStatus TensorNdf::averageChecked(const Footprint& footprint, const SRect& rect, double* value) const {
  const Impl& m = *impl_;
  const double x0 = std::max(rect.x0, -1.0), x1 = std::min(rect.x1, 1.0);
  const double y0 = std::max(rect.y0, -1.0), y1 = std::min(rect.y1, 1.0);
  double integral = 0.0;
  if (x1 > x0 && y1 > y0) {
    Impl::Blend b;
    m.blend(footprint, &b);
    // Blocks touched (bins as NdfPyramid::average finds them); within each block the integral of
    // the piecewise-constant model over the clipped rectangle is a rank-R product of continuous
    // cumulative sums, partial bins weighted by their overlap.
    const double fx0 = (x0 + 1.0) * m.inv_bin, fx1 = (x1 + 1.0) * m.inv_bin;  // bin coordinates from the left
    const double fy0 = (1.0 - y1) * m.inv_bin, fy1 = (1.0 - y0) * m.inv_bin;  // bin coordinates from the top
    const int i0 = std::min(m.res - 1, int(fx0)), i1 = std::min(m.res - 1, int(fx1));
    const int j0 = std::min(m.res - 1, int(fy0)), j1 = std::min(m.res - 1, int(fy1));
    int bx0, bx1, by0, by1, unused;
    m.splitBin(i0, &bx0, &unused);
    m.splitBin(i1, &bx1, &unused);
    m.splitBin(j0, &by0, &unused);
    m.splitBin(j1, &by1, &unused);
    const double full = double(m.bins);
    for (int by = by0; by <= by1; ++by) {
      const double row0 = double(by * m.bins);
      const double ly0 = std::clamp(fy0 - row0, 0.0, full), ly1 = std::clamp(fy1 - row0, 0.0, full);
      if (!(ly1 > ly0)) continue;
      for (int bx = bx0; bx <= bx1; ++bx) {
        const double col0 = double(bx * m.bins);
        const double lx0 = std::clamp(fx0 - col0, 0.0, full), lx1 = std::clamp(fx1 - col0, 0.0, full);
        if (!(lx1 > lx0)) continue;
        const double block_integral =
            m.blockRangeIntegral(b, uint64_t(by) * uint64_t(m.nb) + uint64_t(bx), lx0, lx1, ly0, ly1);
        if (block_integral > 0.0) integral += block_integral * m.bin_area;
      }
    }
  }
  *value = integral / ((rect.x1 - rect.x0) * (rect.y1 - rect.y0));
  return RuntimeStatus::kOk;
}

RuntimeStatus TensorNdf::massChecked(const Footprint& footprint, double* value) const {
  const Impl& m = *impl_;
  if (m.nonneg) {
    format::NdfBlendLevel parts[2];
    *value = m.mixtureMass(parts, m.blender.levels(footprint.x, footprint.y, footprint.sigma, parts));
    return RuntimeStatus::kOk;
  }
  Impl::Blend b;
  m.blend(footprint, &b);
  *value = m.totalMass(b);
  return RuntimeStatus::kOk;
}

RuntimeStatus TensorNdf::pdfChecked(const Footprint& footprint, const SPoint& s, double* value) const {
  const Impl& m = *impl_;
  const int bin = m.binOf(s.x, s.y);
  if (bin < 0) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  if (m.nonneg) {
    // The density sample() reports for the mixture: eval over mass.
    format::NdfBlendLevel parts[2];
    const int n = m.blender.levels(footprint.x, footprint.y, footprint.sigma, parts);
    const double total = m.mixtureMass(parts, n);
    *value = total > 0.0 ? m.imagePointValue(parts, n, bin % m.res, bin / m.res) / total : 0.0;
    return RuntimeStatus::kOk;
  }
  Impl::Blend b;
  m.blend(footprint, &b);
  *value = m.binPdf(b, bin % m.res, bin / m.res);
  return RuntimeStatus::kOk;
}

namespace {

// The walk of a discrete pick: the last entry with positive mass whose running sum passes target
// (rounding may run past the last entry with mass: it is kept); u() gives the position within the
// chosen entry, rescaled to [0, 1).
class MassWalk {
 public:
  explicit MassWalk(double target) : target_(target) {}
  // Offers the next entry's mass; true when it becomes the chosen one.
  bool offer(double mass) {
    if (done_ || !(mass > 0.0)) return false;
    chosen_mass_ = mass;
    if (target_ < before_ + mass) {
      done_ = true;
    } else {
      before_ += mass;
    }
    return true;
  }
  bool done() const { return done_; }
  double chosenMass() const { return chosen_mass_; }
  double u() const {
    const double v = (target_ - before_) / chosen_mass_;
    return v < kOneMinusEpsilon ? (v > 0.0 ? v : 0.0) : kOneMinusEpsilon;
  }

 private:
  double target_, before_ = 0.0, chosen_mass_ = 0.0;
  bool done_ = false;
};

// The bin of a prefix-sum column P (P[k * stride], k = 0..bins, non-decreasing) holding the
// fraction u of its total, and the position within it: the first k with P[k] > u P[bins] gives bin
// k - 1 (a bin of positive width); rounding past the total lands in the last such bin.
double invertPrefix(const float* prefix, int32_t stride, int32_t bins, double u) {
  auto at = [&](int32_t k) { return double(prefix[size_t(k) * size_t(stride)]); };
  const double t = u * at(bins);
  int32_t lo = 0, hi = bins;  // at(lo) <= t, the answer k in (lo, hi]
  if (!(t < at(bins))) {
    while (hi > 1 && !(at(hi - 1) < at(hi))) --hi;
    return double(hi - 1) + kOneMinusEpsilon;
  }
  while (hi - lo > 1) {
    const int32_t mid = (lo + hi) / 2;
    if (at(mid) > t) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  const double f = (t - at(hi - 1)) / (at(hi) - at(hi - 1));
  return double(hi - 1) + (f < kOneMinusEpsilon ? (f > 0.0 ? f : 0.0) : kOneMinusEpsilon);
}

// A point of one stored block of a non-negative asset (C row `row` of group v) drawn from its
// density: a rank-1 term r by c_r times the sums of its A and B columns (the prefix sums' last
// rows), then the column of A and the column of B of that term, each by its prefix sums (for
// an exact block, A's column r is bin r alone). O(R + log B), against the quadtree descent of a
// blend of blocks. false when no term has positive mass.
bool drawFromBlock(const CpGroupView& v, int32_t row, double u1, double u2, CpBlockSample* out) {
  const int32_t rank = v.rank, bins = v.bins;
  const float* c = v.c + size_t(row) * size_t(rank);
  const float* a_total = v.a_prefix + size_t(bins) * size_t(rank);
  const float* b_total = v.b_prefix + size_t(bins) * size_t(rank);
  double total = 0.0;
  for (int32_t r = 0; r < rank; ++r) total += double(c[r]) * double(a_total[r]) * double(b_total[r]);
  if (!(total > 0.0)) return false;
  MassWalk walk(u1 * total);
  int32_t term = 0;
  for (int32_t r = 0; r < rank && !walk.done(); ++r) {
    if (walk.offer(double(c[r]) * double(a_total[r]) * double(b_total[r]))) term = r;
  }
  const double x = invertPrefix(v.a_prefix + term, rank, bins, walk.u());
  const double y = invertPrefix(v.b_prefix + term, rank, bins, u2);
  out->x = float(x);
  out->y = float(y);
  out->i = std::min(bins - 1, int32_t(x));
  out->j = std::min(bins - 1, int32_t(y));
  // Float rounding of the position must not leave the bin.
  if (int32_t(out->x) != out->i) out->x = float(out->i) + 0.5f;
  if (int32_t(out->y) != out->j) out->y = float(out->j) + 0.5f;
  out->pdf = 0.0;  // the caller reports the blend's density
  return true;
}

template <typename MassOf>
uint64_t pickByMass(uint64_t count, double target, MassOf&& mass_of, double* chosen_mass, double* u) {
  MassWalk walk(target);
  uint64_t chosen = 0;
  for (uint64_t k = 0; k < count && !walk.done(); ++k) {
    if (walk.offer(mass_of(k))) chosen = k;
  }
  *chosen_mass = walk.chosenMass();
  *u = walk.u();
  return chosen;
}

}  // namespace

void TensorNdf::Impl::pointInBlock(const CpBlockSample* drawn, uint64_t block, double u1, double u2, SPoint* s, int* bi,
                                   int* bj) const {
  const int bx = int(block % uint64_t(nb)), by = int(block / uint64_t(nb));
  double x, y;
  if (drawn) {
    x = drawn->x;
    y = drawn->y;
    *bi = drawn->i;
    *bj = drawn->j;
  } else {
    x = u1 * bins;
    y = u2 * bins;
    *bi = std::min(bins - 1, int(x));
    *bj = std::min(bins - 1, int(y));
  }
  const int col = bx * bins + *bi, row = by * bins + *bj;
  *s = SPoint{-1.0 + (bx * bins + x) * bin, 1.0 - (by * bins + y) * bin};
  // Rounding of the s-plane conversion must not move the point into a neighbouring bin (pdf()
  // locates the bin from s): fall back to the bin centre in that rare case.
  if (binOf(s->x, s->y) != row * res + col) *s = SPoint{-1.0 + (col + 0.5) * bin, 1.0 - (row + 0.5) * bin};
}

RuntimeStatus TensorNdf::sampleChecked(const Footprint& footprint, double u1, double u2, NdfSample* out) const {
  const Impl& m = *impl_;
  SPoint s;
  int bi, bj;
  if (m.nonneg) {
    // Every term is non-negative, so the blend sum_t w_t NDF_t is a mixture: a centre by its
    // weighted mass w_t M_t, a block of that centre by its mass, and a point of that one block.
    // The density is then eval / mass wherever the point lands, whatever path drew it: no
    // per-block blend of every centre's masses (nb^2 x centres), and one block's point drawn term
    // by term (drawFromBlock).
    format::NdfBlendLevel parts[2];
    const int n = m.blender.levels(footprint.x, footprint.y, footprint.sigma, parts);
    // A row of centres by its weighted mass (the row sums of mixtureMass, whose total pdf() and
    // mass() find too), then a centre of that row by its own.
    double rows[2 * format::kMaxBlendAxis];
    const double total = m.mixtureMass(parts, n, rows);
    if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
    MassWalk row_walk(u1 * total);
    int part = 0, row = 0;
    for (int k = 0, r = 0; k < n && !row_walk.done(); ++k) {
      for (int b = 0; b < parts[k].ny && !row_walk.done(); ++b, ++r) {
        if (row_walk.offer(rows[r])) {
          part = k;
          row = b;
        }
      }
    }
    const format::NdfBlendLevel& chosen = parts[part];
    const int level = chosen.level;
    const double* centre_mass = m.levels[level].centre_mass.data;
    MassWalk walk(row_walk.u() * row_walk.chosenMass());
    size_t centre = 0;
    chosen.forEachInRow(row, [&](int a, double w) {
      const size_t c = chosen.centre(a, row);
      if (walk.offer(w * centre_mass[c])) centre = c;
    });
    u1 = walk.u();
    const Impl::TLevel& lv = m.levels[level];
    const double* masses = lv.mass.data + centre * m.nb2;
    double block_mass;
    const uint64_t block = pickByMass(
        m.nb2, u1 * lv.centre_mass.data[centre], [&](uint64_t k) { return masses[k]; }, &block_mass, &u1);
    // A block with positive mass is never blank (blank blocks weigh 0).
    const TensorIndexEntry& e = lv.index.data[centre * m.nb2 + block];
    CpBlockSample drawn;
    const bool ok = drawFromBlock(m.groups.data[e.group].view, int32_t(e.row), u1, u2, &drawn);
    m.pointInBlock(ok ? &drawn : nullptr, block, u1, u2, &s, &bi, &bj);
    out->s = s;
    // pdf() forms the same quotient. A point whose blended value rounds to 0 (not seen on valid
    // assets) reports density 0, as pdf() does there.
    out->pdf = m.pointValue(parts, n, block, bi, bj) / total;
    return RuntimeStatus::kOk;
  }
  Impl::Blend b;
  m.blend(footprint, &b);
  double masses[Impl::kMassBlocks];
  const double total = m.totalMass(b, masses);
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
  // 1. Block by clamped blended mass; u1 is rescaled to [0, 1) within the chosen block.
  double chosen_mass;
  const uint64_t chosen = pickByMass(
      m.nb2, u1 * total, [&](uint64_t k) { return m.keepsMasses() ? masses[k] : m.blockMass(b, k); }, &chosen_mass,
      &u1);
  // 2. Bin and point inside the block.
  CpMix mix;
  m.mixBlock(b, chosen, &mix);
  // A block whose blended raw mass is positive but whose float range sum rounds to <= 0 is
  // sampled uniformly (binPdf() does the same).
  CpBlockSample drawn;
  const bool ok = mix.blockMass() > 0.0f && mix.sample(u1, u2, &drawn);
  const double p = ok ? drawn.pdf : 1.0 / (double(m.bins) * m.bins);
  m.pointInBlock(ok ? &drawn : nullptr, chosen, u1, u2, &s, &bi, &bj);
  out->s = s;
  out->pdf = combinePdf(chosen_mass, total, p, m.bin_area);
  return RuntimeStatus::kOk;
}

RuntimeStatus TensorNdf::imageChecked(const Footprint& footprint, float* out) const {
  const Impl& m = *impl_;
  Impl::Blend b;
  m.blend(footprint, &b);
  CpMix mix;
  for (int by = 0; by < m.nb; ++by) {
    for (int bx = 0; bx < m.nb; ++bx) {
      m.mixBlock(b, uint64_t(by) * uint64_t(m.nb) + uint64_t(bx), &mix);
      for (int j = 0; j < m.bins; ++j) {
        float* dst = out + size_t(by * m.bins + j) * size_t(m.res) + size_t(bx * m.bins);
        for (int i = 0; i < m.bins; ++i) dst[i] = mix.value(i, j);
      }
    }
  }
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
