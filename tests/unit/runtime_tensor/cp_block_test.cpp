// SPDX-License-Identifier: Apache-2.0
// Runtime CP block queries: point values, prefix-sum range averages, and the exact agreement of
// sample() and pdf(); the departures of plain (signed) CP from the identities are measured.
#include <glintbake/runtime/cp_block.h>

#include "cp_groups.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

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
