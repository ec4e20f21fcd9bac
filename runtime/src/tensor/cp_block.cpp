// SPDX-License-Identifier: Apache-2.0
// Blended queries on CP-compressed blocks: rank-R products, prefix-sum range sums and the
// quadtree sampler (Deng et al. 2022, sec. 4.3).
#include <glintbake/runtime/cp_block.h>

#include "lane_sum.h"

#include <cmath>

namespace glintbake::runtime {

RuntimeStatus validateCpGroupView(const CpGroupView& v) {
  if (v.bins < 1 || v.bins > kCpMaxBins || v.rank < 1 || v.rank > kCpMaxRank || v.blocks < 1)
    return RuntimeStatus::kInvalidArgument;
  if (!v.a || !v.b || !v.c || !v.a_prefix || !v.b_prefix) return RuntimeStatus::kInvalidArgument;
  if (v.identity_a && v.rank != v.bins) return RuntimeStatus::kInvalidArgument;
  return RuntimeStatus::kOk;
}

RuntimeStatus CpMix::init(const CpBlendTerm* terms, int32_t count) {
  group_count_ = 0;
  exact_count_ = 0;
  bins_ = 0;
  if (count < 0 || count > kCpMaxBlend || (count > 0 && !terms)) return RuntimeStatus::kInvalidArgument;
  for (int32_t t = 0; t < count; ++t) {
    const CpBlendTerm& term = terms[t];
    if (!term.group || validateCpGroupView(*term.group) != RuntimeStatus::kOk || term.block < 0 ||
        term.block >= term.group->blocks || !std::isfinite(term.weight) || (bins_ != 0 && term.group->bins != bins_)) {
      group_count_ = 0;
      exact_count_ = 0;
      bins_ = 0;
      return RuntimeStatus::kInvalidArgument;
    }
    if (term.weight == 0.0f) continue;
    bins_ = term.group->bins;
    if (term.group->identity_a) {
      const int32_t t_exact = exact_count_++;
      exact_[t_exact] = term.group;
      exact_c_[t_exact] = term.group->c + static_cast<size_t>(term.block) * term.group->rank;
      exact_w_[t_exact] = term.weight;
      const double m =
          term.mass >= 0.0f ? double(term.weight) * term.mass : double(exactRangeSum(t_exact, 0, bins_, 0, bins_));
      exact_m_[t_exact] = m > 0.0 ? m : 0.0;
      continue;
    }
    int32_t g = 0;
    while (g < group_count_ && groups_[g] != term.group) ++g;
    const int32_t rank = term.group->rank;
    if (g == group_count_) {
      if (group_count_ == kCpMaxGroups) continue;
      groups_[g] = term.group;
      for (int32_t r = 0; r < rank; ++r) coef_[g][r] = 0.0f;
      ++group_count_;
    }
    const float* c = term.group->c + static_cast<size_t>(term.block) * rank;
    for (int32_t r = 0; r < rank; ++r) coef_[g][r] += term.weight * c[r];
  }
  group_mass_ = mix_mass_ = 0.0;
  if (exact_count_ > 0) {
    if (group_count_ > 0) {
      const float m = groupRangeSum(0, bins_, 0, bins_);
      group_mass_ = m > 0.0f ? double(m) : 0.0;
    }
    mix_mass_ = group_mass_;
    for (int32_t t = 0; t < exact_count_; ++t) mix_mass_ += exact_m_[t];
  }
  return RuntimeStatus::kOk;
}

float CpMix::exactValue(int32_t t, int32_t i, int32_t j) const {
  const CpGroupView& v = *exact_[t];
  return exact_w_[t] * exact_c_[t][i] * v.b[static_cast<size_t>(j) * v.rank + i];
}

float CpMix::exactRangeSum(int32_t t, int32_t i0, int32_t i1, int32_t j0, int32_t j1) const {
  // Column i of an exact block is C(k, i) times column i of B; B's prefix sums run down the rows.
  const CpGroupView& v = *exact_[t];
  const float* p0 = v.b_prefix + static_cast<size_t>(j0) * v.rank;
  const float* p1 = v.b_prefix + static_cast<size_t>(j1) * v.rank;
  const float* c = exact_c_[t];
  float lanes[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  laneAccumulate<float>(
      i1 - i0, [&](int32_t r) { return c[i0 + r] * (p1[i0 + r] - p0[i0 + r]); }, exact_w_[t], lanes);
  return laneTotal(lanes);
}

float CpMix::rawValue(int32_t i, int32_t j) const {
  if (i < 0 || j < 0 || i >= bins_ || j >= bins_) return 0.0f;
  float sum = 0.0f;
  for (int32_t t = 0; t < exact_count_; ++t) sum += exactValue(t, i, j);
  for (int32_t g = 0; g < group_count_; ++g) {
    const CpGroupView& v = *groups_[g];
    const int32_t rank = v.rank;
    const float* a = v.a + static_cast<size_t>(i) * rank;
    const float* b = v.b + static_cast<size_t>(j) * rank;
    sum += laneDot3(coef_[g], a, b, rank);
  }
  return sum;
}

float CpMix::value(int32_t i, int32_t j) const {
  const float v = rawValue(i, j);
  return v > 0.0f ? v : 0.0f;
}

float CpMix::rawRangeSum(int32_t i0, int32_t i1, int32_t j0, int32_t j1) const {
  if (i0 < 0 || j0 < 0 || i1 > bins_ || j1 > bins_ || i0 >= i1 || j0 >= j1) return 0.0f;
  float sum = groupRangeSum(i0, i1, j0, j1);
  for (int32_t t = 0; t < exact_count_; ++t) sum += exactRangeSum(t, i0, i1, j0, j1);
  return sum;
}

float CpMix::groupRangeSum(int32_t i0, int32_t i1, int32_t j0, int32_t j1) const {
  float sum = 0.0f;
  for (int32_t g = 0; g < group_count_; ++g) {
    const CpGroupView& v = *groups_[g];
    const int32_t rank = v.rank;
    const float* pa0 = v.a_prefix + static_cast<size_t>(i0) * rank;
    const float* pa1 = v.a_prefix + static_cast<size_t>(i1) * rank;
    const float* pb0 = v.b_prefix + static_cast<size_t>(j0) * rank;
    const float* pb1 = v.b_prefix + static_cast<size_t>(j1) * rank;
    const float* coef = coef_[g];
    float da[kCpMaxRank], db[kCpMaxRank];
    for (int32_t r = 0; r < rank; ++r) {
      da[r] = pa1[r] - pa0[r];
      db[r] = pb1[r] - pb0[r];
    }
    sum += laneDot3(coef, da, db, rank);
  }
  return sum;
}

float CpMix::rangeAverage(int32_t i0, int32_t i1, int32_t j0, int32_t j1) const {
  if (i0 < 0) i0 = 0;
  if (j0 < 0) j0 = 0;
  if (i1 > bins_ - 1) i1 = bins_ - 1;
  if (j1 > bins_ - 1) j1 = bins_ - 1;
  if (i0 > i1 || j0 > j1) return 0.0f;
  const float sum = rawRangeSum(i0, i1 + 1, j0, j1 + 1);
  const float count = static_cast<float>((i1 - i0 + 1) * (j1 - j0 + 1));
  return sum > 0.0f ? sum / count : 0.0f;
}

float CpMix::blockMass() const {
  if (exact_count_ > 0) return float(mix_mass_);  // the components' clamped masses (sample's mixture)
  const float sum = rawRangeSum(0, bins_, 0, bins_);
  return sum > 0.0f ? sum : 0.0f;
}

void CpMix::childWeights(int32_t component, int32_t x0, int32_t xm, int32_t x1, int32_t y0, int32_t ym, int32_t y1,
                         float w[4]) const {
  float s00 = 0.0f, s10 = 0.0f, s01 = 0.0f, s11 = 0.0f;
  if (component >= 0) {
    // An empty side (width 0) sums to exactly zero.
    s00 = x0 < xm && y0 < ym ? exactRangeSum(component, x0, xm, y0, ym) : 0.0f;
    s10 = xm < x1 && y0 < ym ? exactRangeSum(component, xm, x1, y0, ym) : 0.0f;
    s01 = x0 < xm && ym < y1 ? exactRangeSum(component, x0, xm, ym, y1) : 0.0f;
    s11 = xm < x1 && ym < y1 ? exactRangeSum(component, xm, x1, ym, y1) : 0.0f;
  }
  for (int32_t g = 0; component < 0 && g < group_count_; ++g) {
    const CpGroupView& v = *groups_[g];
    const int32_t rank = v.rank;
    const float* pax0 = v.a_prefix + static_cast<size_t>(x0) * rank;
    const float* paxm = v.a_prefix + static_cast<size_t>(xm) * rank;
    const float* pax1 = v.a_prefix + static_cast<size_t>(x1) * rank;
    const float* pby0 = v.b_prefix + static_cast<size_t>(y0) * rank;
    const float* pbym = v.b_prefix + static_cast<size_t>(ym) * rank;
    const float* pby1 = v.b_prefix + static_cast<size_t>(y1) * rank;
    const float* coef = coef_[g];
    float left[kCpMaxRank], right[kCpMaxRank], top[kCpMaxRank], bottom[kCpMaxRank];
    for (int32_t r = 0; r < rank; ++r) {
      left[r] = paxm[r] - pax0[r];
      right[r] = pax1[r] - paxm[r];
      top[r] = (pbym[r] - pby0[r]) * coef[r];
      bottom[r] = (pby1[r] - pbym[r]) * coef[r];
    }
    s00 += laneDot(left, top, rank);
    s10 += laneDot(right, top, rank);
    s01 += laneDot(left, bottom, rank);
    s11 += laneDot(right, bottom, rank);
  }
  // Empty children (a side of width 0) have exactly zero sums.
  w[0] = s00 > 0.0f ? s00 : 0.0f;
  w[1] = s10 > 0.0f ? s10 : 0.0f;
  w[2] = s01 > 0.0f ? s01 : 0.0f;
  w[3] = s11 > 0.0f ? s11 : 0.0f;
}

namespace {

// The split of one quadtree node and the probabilities of its four children (left-top,
// right-top, left-bottom, right-bottom). Shared verbatim by sample() and pdf() so that both
// compute bit-identical probabilities.
struct Node {
  int32_t x0, x1, y0, y1;
  int32_t xm() const { return x0 + (x1 - x0 + 1) / 2; }  // width 1: xm == x1, right side empty
  int32_t ym() const { return y0 + (y1 - y0 + 1) / 2; }
  bool leaf() const { return x1 - x0 <= 1 && y1 - y0 <= 1; }
};

void childProbabilities(const Node& n, const float w[4], double q[4]) {
  const double total = ((static_cast<double>(w[0]) + w[1]) + w[2]) + w[3];
  if (total > 0.0) {
    for (int c = 0; c < 4; ++c) q[c] = w[c] / total;
    return;
  }
  // Every child clamped to zero although the parent had mass: fall back to uniform over the
  // non-empty children.
  const bool has_right = n.xm() < n.x1, has_bottom = n.ym() < n.y1;
  const bool present[4] = {true, has_right, has_bottom, has_right && has_bottom};
  const double share = 1.0 / (1 + has_right + has_bottom + (has_right && has_bottom));
  for (int c = 0; c < 4; ++c) q[c] = present[c] ? share : 0.0;
}

void descendInto(Node& n, int child) {
  const int32_t xm = n.xm(), ym = n.ym();
  if (child & 1) {
    n.x0 = xm;
  } else {
    n.x1 = xm;
  }
  if (child & 2) {
    n.y0 = ym;
  } else {
    n.y1 = ym;
  }
}

constexpr double kLargestBelowOne = 0x1.fffffffffffffp-1;

}  // namespace

bool CpMix::descend(int32_t component, double u1, double u2, CpBlockSample* out) const {
  Node n{0, bins_, 0, bins_};
  double p = 1.0;
  while (!n.leaf()) {
    float w[4];
    childWeights(component, n.x0, n.xm(), n.x1, n.y0, n.ym(), n.y1, w);
    double q[4];
    childProbabilities(n, w, q);
    // Column first (u1), then the row within the column (u2); each uniform is rescaled into the
    // chosen interval so it stays uniform for the next level.
    const double p_left = q[0] + q[2], p_right = q[1] + q[3];
    int child = 0;
    if (p_right == 0.0 || (u1 < p_left && p_left > 0.0)) {
      u1 = p_left > 0.0 ? u1 / p_left : u1;
    } else {
      u1 = p_left > 0.0 ? (u1 - p_left) / p_right : u1;
      child = 1;
    }
    const double p_top_col = q[child], p_bottom_col = q[child + 2];
    const double p_col = p_top_col + p_bottom_col;
    if (p_bottom_col == 0.0 || (u2 * p_col < p_top_col && p_top_col > 0.0)) {
      u2 = p_bottom_col > 0.0 ? u2 * p_col / p_top_col : u2;
    } else {
      u2 = p_top_col > 0.0 ? (u2 * p_col - p_top_col) / p_bottom_col : u2;
      child += 2;
    }
    p *= q[child];
    descendInto(n, child);
  }
  u1 = u1 < kLargestBelowOne ? (u1 > 0.0 ? u1 : 0.0) : kLargestBelowOne;
  u2 = u2 < kLargestBelowOne ? (u2 > 0.0 ? u2 : 0.0) : kLargestBelowOne;
  out->i = n.x0;
  out->j = n.y0;
  // float(i + u) can round up to i + 1 for large i: keep the point inside its bin.
  float x = static_cast<float>(n.x0 + u1), y = static_cast<float>(n.y0 + u2);
  if (x >= static_cast<float>(n.x0 + 1)) x = std::nextafter(static_cast<float>(n.x0 + 1), 0.0f);
  if (y >= static_cast<float>(n.y0 + 1)) y = std::nextafter(static_cast<float>(n.y0 + 1), 0.0f);
  out->x = x;
  out->y = y;
  out->pdf = p;
  return true;
}

double CpMix::descentPdf(int32_t component, int32_t i, int32_t j) const {
  Node n{0, bins_, 0, bins_};
  double p = 1.0;
  while (!n.leaf()) {
    float w[4];
    childWeights(component, n.x0, n.xm(), n.x1, n.y0, n.ym(), n.y1, w);
    double q[4];
    childProbabilities(n, w, q);
    const int child = (i >= n.xm() ? 1 : 0) + (j >= n.ym() ? 2 : 0);
    if (q[child] == 0.0) return 0.0;
    p *= q[child];
    descendInto(n, child);
  }
  return p;
}

double CpMix::mixturePdf(int32_t i, int32_t j) const {
  if (!(mix_mass_ > 0.0)) return 0.0;
  double density = group_mass_ > 0.0 ? group_mass_ * descentPdf(-1, i, j) : 0.0;
  for (int32_t t = 0; t < exact_count_; ++t) {
    const float v = exactValue(t, i, j);
    if (v > 0.0f) density += double(v);
  }
  return density / mix_mass_;
}

bool CpMix::sample(double u1, double u2, CpBlockSample* out) const {
  if (!out || !(blockMass() > 0.0f)) return false;
  if (exact_count_ == 0) return descend(-1, u1, u2, out);
  // A mixture: the component by its clamped mass (u1 rescaled into it), then the quadtree within.
  const double target = u1 * mix_mass_;
  double before = 0.0, chosen_mass = 0.0;
  int32_t chosen = -2;
  for (int32_t c = group_count_ > 0 ? -1 : 0; c < exact_count_; ++c) {
    const double m = componentMass(c);
    if (!(m > 0.0)) continue;
    chosen = c;
    chosen_mass = m;
    if (target < before + m) break;
    before += m;  // rounding may run past the last component with mass: it is kept
  }
  if (chosen == -2) return false;
  u1 = (target - before) / chosen_mass;
  u1 = u1 < kLargestBelowOne ? (u1 > 0.0 ? u1 : 0.0) : kLargestBelowOne;
  if (!descend(chosen, u1, u2, out)) return false;
  out->pdf = mixturePdf(out->i, out->j);
  return true;
}

double CpMix::pdf(int32_t i, int32_t j) const {
  if (i < 0 || j < 0 || i >= bins_ || j >= bins_ || !(blockMass() > 0.0f)) return 0.0;
  return exact_count_ == 0 ? descentPdf(-1, i, j) : mixturePdf(i, j);
}

double CpMix::pdfAt(float x, float y) const {
  if (!(x >= 0.0f) || !(y >= 0.0f)) return 0.0;
  return pdf(static_cast<int32_t>(std::floor(x)), static_cast<int32_t>(std::floor(y)));
}

}  // namespace glintbake::runtime
