// SPDX-License-Identifier: Apache-2.0
// Runtime CP block queries: point values, prefix-sum range averages, and the exact agreement of
// sample() and pdf(); the departures of plain (signed) CP from the identities are measured.
#include <glintbake/runtime/cp_block.h>

#include "cp_groups.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

namespace glintbake::runtime {
namespace {

using testing::makeBlend;
using testing::makeGroup;
using testing::Uniforms;

double directValue(const CpBlendTerm* terms, int count, int i, int j) {
  double sum = 0.0;
  for (int t = 0; t < count; ++t) {
    const CpGroupView& v = *terms[t].group;
    for (int r = 0; r < v.rank; ++r)
      sum += static_cast<double>(terms[t].weight) * v.a[i * v.rank + r] * v.b[j * v.rank + r] *
             v.c[terms[t].block * v.rank + r];
  }
  return sum;
}

TEST(CpBlock, PointValueIsTheBlendOfRankRProducts) {
  auto g0 = makeGroup(1, false), g1 = makeGroup(2, false, 12);
  const CpBlendTerm terms[3] = {{&g0->view, 5, 0.5f}, {&g0->view, 9, 0.25f}, {&g1->view, 2, 0.25f}};
  CpMix mix;
  ASSERT_EQ(mix.init(terms, 3), RuntimeStatus::kOk);
  for (int j = 0; j < 32; j += 3) {
    for (int i = 0; i < 32; i += 2) {
      const double expected = directValue(terms, 3, i, j);
      EXPECT_NEAR(mix.rawValue(i, j), expected, 1e-5 * (1.0 + std::abs(expected)));
      EXPECT_EQ(mix.value(i, j), std::max(0.0f, mix.rawValue(i, j)));
    }
  }
  EXPECT_EQ(mix.value(-1, 0), 0.0f);
  EXPECT_EQ(mix.value(0, 32), 0.0f);
}

TEST(CpBlock, RangeAverageEqualsMeanOfPointValuesForNonnegativeModels) {
  auto g0 = makeGroup(3, true), g1 = makeGroup(4, true);
  const CpMix mix = makeBlend(*g0, *g1);
  ASSERT_FALSE(mix.empty());
  Uniforms u(5);
  for (int n = 0; n < 300; ++n) {
    int i0 = static_cast<int>(u.next() * 32), i1 = static_cast<int>(u.next() * 32);
    int j0 = static_cast<int>(u.next() * 32), j1 = static_cast<int>(u.next() * 32);
    if (i0 > i1) std::swap(i0, i1);
    if (j0 > j1) std::swap(j0, j1);
    double mean = 0.0, peak = 0.0;
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        mean += mix.value(i, j);
        peak = std::max(peak, static_cast<double>(mix.value(i, j)));
      }
    }
    mean /= (i1 - i0 + 1) * (j1 - j0 + 1);
    EXPECT_NEAR(mix.rangeAverage(i0, i1, j0, j1), mean, 1e-5 * std::max(mean, 1e-3 * peak))
        << "[" << i0 << "," << i1 << "] x [" << j0 << "," << j1 << "]";
  }
  // A single bin's range sum is its point value; the whole block is its mass.
  EXPECT_NEAR(mix.rawRangeSum(7, 8, 11, 12), mix.rawValue(7, 11), 1e-5 * (1.0 + mix.rawValue(7, 11)));
  EXPECT_NEAR(mix.rangeAverage(0, 31, 0, 31) * 1024.0f, mix.blockMass(), 1e-3 * mix.blockMass());
}

TEST(CpBlock, SampledPdfEqualsPdfExactly) {
  for (bool nonneg : {true, false}) {
    auto g0 = makeGroup(6, nonneg), g1 = makeGroup(7, nonneg);
    const CpMix mix = makeBlend(*g0, *g1);
    Uniforms u(8);
    for (int n = 0; n < 20000; ++n) {
      CpBlockSample s;
      ASSERT_TRUE(mix.sample(u.next(), u.next(), &s));
      ASSERT_GE(s.x, s.i);
      ASSERT_LT(s.x, s.i + 1);
      ASSERT_GE(s.y, s.j);
      ASSERT_LT(s.y, s.j + 1);
      ASSERT_GT(s.pdf, 0.0);
      ASSERT_EQ(s.pdf, mix.pdf(s.i, s.j)) << "nonneg " << nonneg;
      ASSERT_EQ(s.pdf, mix.pdfAt(s.x, s.y));
    }
  }
}

TEST(CpBlock, PdfSumsToOneAndMatchesValueForNonnegativeModels) {
  auto g0 = makeGroup(9, true), g1 = makeGroup(10, true);
  const CpMix mix = makeBlend(*g0, *g1);
  const double mass = mix.blockMass();
  double total = 0.0, worst = 0.0, peak = 0.0;
  for (int j = 0; j < 32; ++j) {
    for (int i = 0; i < 32; ++i) peak = std::max(peak, static_cast<double>(mix.value(i, j)));
  }
  for (int j = 0; j < 32; ++j) {
    for (int i = 0; i < 32; ++i) {
      total += mix.pdf(i, j);
      worst = std::max(worst, std::abs(mix.pdf(i, j) * mass - mix.value(i, j)) / peak);
    }
  }
  EXPECT_NEAR(total, 1.0, 1e-9);
  EXPECT_LT(worst, 1e-5);
}

// Plain CP dips below zero: report the negative mass and how far pdf() strays from value()/mass.
TEST(CpBlock, MeasuresSignedModelDepartures) {
  for (bool nonneg : {false, true}) {
    auto g0 = makeGroup(11, nonneg), g1 = makeGroup(12, nonneg);
    const CpMix mix = makeBlend(*g0, *g1);
    double negative = 0.0, positive = 0.0, pdf_total = 0.0, gap = 0.0, clamped_total = 0.0;
    int negative_bins = 0;
    for (int j = 0; j < 32; ++j) {
      for (int i = 0; i < 32; ++i) {
        const double v = mix.rawValue(i, j);
        (v < 0.0 ? negative : positive) += std::abs(v);
        negative_bins += v < 0.0;
        clamped_total += mix.value(i, j);
        pdf_total += mix.pdf(i, j);
      }
    }
    for (int j = 0; j < 32; ++j) {
      for (int i = 0; i < 32; ++i) gap += std::abs(mix.pdf(i, j) - mix.value(i, j) / clamped_total);
    }
    std::printf("%s CP: negative mass %.4f%% of |values| in %d of 1024 bins; pdf vs value/mass L1 gap %.4f%%\n",
                nonneg ? "non-negative" : "plain", 100.0 * negative / (negative + positive), negative_bins,
                100.0 * gap);
    EXPECT_NEAR(pdf_total, 1.0, 1e-9);
    if (nonneg) {
      EXPECT_EQ(negative_bins, 0);
      EXPECT_LT(gap, 1e-4);
    }
  }
}

// Exact blocks (A = identity, tensorpack's exact levels) beside a compressed group: a footprint
// over a wide exact level blends hundreds of them, more than a mix has group slots. Every term
// counts, and sample() follows pdf(), which sums to 1 and equals value / mass.
struct ExactBlock {
  std::vector<float> a, b, c, a_prefix, b_prefix;
  CpGroupView view;
};

std::unique_ptr<ExactBlock> makeExactBlock(uint64_t seed) {
  constexpr int kBins = 32;
  auto e = std::make_unique<ExactBlock>();
  e->a.assign(kBins * kBins, 0.0f);
  for (int i = 0; i < kBins; ++i) e->a[i * kBins + i] = 1.0f;
  // A few narrow peaks on a faint floor, like a glinty NDF block; some blocks all zero.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  e->b.assign(kBins * kBins, seed % 7 == 0 ? 0.0f : 1e-3f);
  for (int p = 0; p < int(seed % 4); ++p) {
    const int i = int(u(rng) * kBins), j = int(u(rng) * kBins);
    e->b[j * kBins + i] += 5.0f * u(rng);
  }
  e->c.assign(kBins, 1.0f);
  e->a_prefix = bake::tensor::buildPrefixSums(e->a, kBins, kBins);
  e->b_prefix = bake::tensor::buildPrefixSums(e->b, kBins, kBins);
  e->view =
      CpGroupView{kBins, kBins, 1, e->a.data(), e->b.data(), e->c.data(), e->a_prefix.data(), e->b_prefix.data(), true};
  return e;
}

TEST(CpBlock, ExactBlocksBeyondTheGroupSlotsAllCount) {
  constexpr int kExact = 3 * kCpMaxGroups;
  std::vector<std::unique_ptr<ExactBlock>> blocks;
  for (int t = 0; t < kExact; ++t) blocks.push_back(makeExactBlock(uint64_t(t)));
  auto cp = makeGroup(21, true);
  std::vector<CpBlendTerm> terms;
  Uniforms u(22);
  terms.push_back({&cp->view, 4, 0.05f});
  terms.push_back({&cp->view, 9, 0.03f});
  for (int t = 0; t < kExact; ++t) terms.push_back({&blocks[size_t(t)]->view, 0, float(0.5 + u.next()) / kExact});
  CpMix mix;
  ASSERT_EQ(mix.init(terms.data(), int32_t(terms.size())), RuntimeStatus::kOk);
  double peak = 0.0, direct_mass = 0.0;
  for (int j = 0; j < 32; ++j) {
    for (int i = 0; i < 32; ++i) {
      const double expected = directValue(terms.data(), int(terms.size()), i, j);
      ASSERT_NEAR(mix.rawValue(i, j), expected, 1e-5 * (1.0 + std::abs(expected))) << i << "," << j;
      peak = std::max(peak, expected);
      direct_mass += expected;
    }
  }
  EXPECT_NEAR(mix.blockMass(), direct_mass, 1e-5 * direct_mass);
  EXPECT_NEAR(
      mix.rawRangeSum(3, 20, 5, 9),
      [&] {
        double s = 0.0;
        for (int j = 5; j < 9; ++j) {
          for (int i = 3; i < 20; ++i) s += mix.rawValue(i, j);
        }
        return s;
      }(),
      1e-4 * direct_mass);
  const double mass = mix.blockMass();
  double total = 0.0, worst = 0.0;
  std::vector<double> pdf(32 * 32);
  for (int j = 0; j < 32; ++j) {
    for (int i = 0; i < 32; ++i) {
      pdf[size_t(j * 32 + i)] = mix.pdf(i, j);
      total += pdf[size_t(j * 32 + i)];
      worst = std::max(worst, std::abs(pdf[size_t(j * 32 + i)] * mass - mix.value(i, j)) / peak);
    }
  }
  EXPECT_NEAR(total, 1.0, 1e-5);
  EXPECT_LT(worst, 1e-5);
  // Samples land where pdf() says: the sample's pdf is pdf() bit for bit, and a chi-square test
  // of the bin counts against it (bins expecting at least 5 samples) passes.
  constexpr int kSamples = 100000;
  std::vector<double> count(32 * 32, 0.0);
  for (int n = 0; n < kSamples; ++n) {
    CpBlockSample s;
    ASSERT_TRUE(mix.sample(u.next(), u.next(), &s));
    ASSERT_EQ(s.pdf, mix.pdf(s.i, s.j));
    ASSERT_GE(s.x, s.i);
    ASSERT_LT(s.x, s.i + 1);
    count[size_t(s.j * 32 + s.i)] += 1.0;
  }
  double chi2 = 0.0, rest_expected = 0.0, rest_seen = 0.0;
  int dof = 0;
  for (size_t k = 0; k < count.size(); ++k) {
    const double expected = pdf[k] * kSamples;
    if (expected >= 5.0) {
      chi2 += (count[k] - expected) * (count[k] - expected) / expected;
      ++dof;
    } else {
      rest_expected += expected;
      rest_seen += count[k];
    }
  }
  if (rest_expected > 0.0) chi2 += (rest_seen - rest_expected) * (rest_seen - rest_expected) / rest_expected;
  ASSERT_GT(dof, 100);
  // Mean dof, standard deviation sqrt(2 dof): 5 standard deviations.
  EXPECT_LT(chi2, dof + 5.0 * std::sqrt(2.0 * dof)) << "dof " << dof;
}

TEST(CpBlock, RejectsInvalidBlends) {
  auto g0 = makeGroup(13, false, 8, 16);
  CpMix mix;
  const CpBlendTerm bad_block[1] = {{&g0->view, 16, 1.0f}};
  EXPECT_EQ(mix.init(bad_block, 1), RuntimeStatus::kInvalidArgument);
  EXPECT_TRUE(mix.empty());
  EXPECT_EQ(mix.value(0, 0), 0.0f);
  const CpBlendTerm nan_weight[1] = {{&g0->view, 0, std::nanf("")}};
  EXPECT_EQ(mix.init(nan_weight, 1), RuntimeStatus::kInvalidArgument);
  CpGroupView broken = g0->view;
  broken.rank = kCpMaxRank + 1;
  const CpBlendTerm bad_view[1] = {{&broken, 0, 1.0f}};
  EXPECT_EQ(mix.init(bad_view, 1), RuntimeStatus::kInvalidArgument);
  CpBlendTerm many[kCpMaxBlend + 1];
  for (auto& t : many) t = {&g0->view, 0, 0.1f};
  EXPECT_EQ(mix.init(many, kCpMaxBlend + 1), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(mix.init(many, 0), RuntimeStatus::kOk);
  CpBlockSample s;
  EXPECT_FALSE(mix.sample(0.5, 0.5, &s));
  EXPECT_EQ(mix.pdf(0, 0), 0.0);
}

}  // namespace
}  // namespace glintbake::runtime
