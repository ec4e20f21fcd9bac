// SPDX-License-Identifier: Apache-2.0
// FlakeNdf (runtime) against the reference evaluator: eval, image, mass and average equal the
// reference to float rounding; samples follow their pdf (chi-square) and pdf == eval / mass.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/format/numbers.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/flake_ndf.h>

#include "../../stats/chi_square.h"
#include "../reference/test_maps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace glintbake {
namespace {

using runtime::FlakeNdf;
using runtime::Footprint;
using runtime::RuntimeStatus;
using runtime::SPoint;

// A normal map seen through the runtime's texel-source interface.
runtime::InterleavedTexels mapTexels(const bake::NormalMap& map) {
  return runtime::InterleavedTexels(map.width, map.height, map.wrap == bake::Wrap::kRepeat, map.normals.data(), 3);
}

bake::NormalMap mapOf(bake::MapKind kind, int size, uint64_t seed) {
  bake::MapParams p;
  p.size = size;
  p.seed = seed;
  return bake::generateMap(kind, p);
}

struct Fixture {
  bake::NormalMap map;
  reference::FlakeSet set;
  FlakeNdf ndf;
  Fixture(bake::NormalMap m, int rate = 1, int res = 64) : map(std::move(m)) {
    set = reference::buildFlakes(map, rate);
    const auto texels = mapTexels(map);
    EXPECT_EQ(ndf.build(texels, rate, reference::kDefaultSigmaR, res), RuntimeStatus::kOk);
  }
};

// Points of the s-plane where the NDF is not negligible: the means of random flakes' lobes.
std::vector<SPoint> probePoints(const Fixture& f, const reference::Footprint& fp, std::mt19937_64& rng) {
  std::vector<reference::FlakeLobe> lobes = reference::footprintLobes(f.set, fp, reference::kDefaultSigmaR);
  std::vector<SPoint> points;
  std::uniform_int_distribution<size_t> pick(0, lobes.size() - 1);
  std::normal_distribution<double> jitter(0.0, 0.01);
  for (int i = 0; i < 12; ++i) {
    const reference::FlakeLobe& l = lobes[pick(rng)];
    points.push_back(
        {std::clamp(l.mean[0] + jitter(rng), -0.999, 0.999), std::clamp(l.mean[1] + jitter(rng), -0.999, 0.999)});
  }
  std::uniform_real_distribution<double> any(-0.7, 0.7);
  for (int i = 0; i < 4; ++i) points.push_back({any(rng), any(rng)});
  return points;
}

void expectEvalMatchesReference(const Fixture& f, double sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(-0.3 * f.map.width, 1.3 * f.map.width);
  for (int trial = 0; trial < 6; ++trial) {
    const reference::Footprint rfp{pos(rng), pos(rng), sigma};
    if (f.map.wrap == bake::Wrap::kClamp && (rfp.x < 0 || rfp.y < 0 || rfp.x > f.map.width || rfp.y > f.map.height))
      continue;
    const Footprint fp{rfp.x, rfp.y, sigma};
    double peak = 0.0;
    std::vector<std::pair<double, double>> values;
    for (const SPoint& s : probePoints(f, rfp, rng)) {
      double v = -1.0;
      ASSERT_EQ(f.ndf.eval(fp, s, &v), RuntimeStatus::kOk);
      const double r = reference::evalPndf(f.set, rfp, s.x, s.y, reference::kDefaultSigmaR);
      values.push_back({v, r});
      peak = std::max(peak, r);
    }
    for (const auto& [v, r] : values) {
      EXPECT_NEAR(v, r, 2e-5 * r + 1e-6 * peak) << "sigma " << sigma << " at (" << rfp.x << ", " << rfp.y << ")";
    }
    double mass = 0.0;
    ASSERT_EQ(f.ndf.mass(fp, &mass), RuntimeStatus::kOk);
    EXPECT_NEAR(mass, reference::footprintWeight(f.set, rfp), 1e-6 * mass);
  }
}

TEST(FlakeNdf, EvalMatchesReferenceOnEveryMapKind) {
  const bake::MapKind kinds[] = {bake::MapKind::kBeckmann, bake::MapKind::kBrushed, bake::MapKind::kScratches,
                                 bake::MapKind::kFlakes};
  uint64_t seed = 1;
  for (bake::MapKind kind : kinds) {
    Fixture f(mapOf(kind, 64, seed));
    for (double sigma : {0.3, 1.0, 2.5, 6.0}) expectEvalMatchesReference(f, sigma, seed++);
  }
}

TEST(FlakeNdf, EvalMatchesReferenceOnClampedAndSubSampledMaps) {
  Fixture clamped(reference::testing::wavyMap(48, 40, 0.3, bake::Wrap::kClamp));
  for (double sigma : {0.5, 2.0, 7.0}) expectEvalMatchesReference(clamped, sigma, 11);
  Fixture rated(reference::testing::wavyMap(24, 24, 0.3), 3);
  for (double sigma : {0.4, 1.5}) expectEvalMatchesReference(rated, sigma, 12);
  // A footprint wider than a small repeating map sees several periodic images of every flake.
  Fixture tiny(mapOf(bake::MapKind::kBeckmann, 8, 5));
  expectEvalMatchesReference(tiny, 5.0, 13);
}

TEST(FlakeNdf, ImageMatchesReferenceBinAverages) {
  Fixture f(mapOf(bake::MapKind::kFlakes, 64, 3), 1, 64);
  for (double sigma : {0.7, 3.0}) {
    const Footprint fp{20.3, 41.7, sigma};
    std::vector<float> img(64 * 64);
    ASSERT_EQ(f.ndf.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
    const std::vector<double> ref =
        reference::binAveragedImage(f.set, {fp.x, fp.y, sigma}, reference::kDefaultSigmaR, 64);
    double diff = 0.0, total = 0.0;
    for (size_t i = 0; i < img.size(); ++i) {
      diff += std::fabs(img[i] - ref[i]);
      total += ref[i];
    }
    EXPECT_LT(diff / total, 1e-5) << "sigma " << sigma;
  }
}

TEST(FlakeNdf, AverageIsTheMeanOfTheImageBins) {
  Fixture f(mapOf(bake::MapKind::kScratches, 64, 4), 1, 32);
  const Footprint fp{33.0, 12.5, 1.7};
  std::vector<float> img(32 * 32);
  ASSERT_EQ(f.ndf.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
  const double bin = 2.0 / 32;
  // Rectangles of whole bins inside the unit disk, where image() and average() agree exactly.
  for (int i0 : {10, 13}) {
    for (int j0 : {12, 15}) {
      const int w = 4, h = 3;
      double mean = 0.0;
      for (int j = j0; j < j0 + h; ++j)
        for (int i = i0; i < i0 + w; ++i) mean += img[size_t(j) * 32 + i];
      mean /= w * h;
      runtime::SRect r{-1.0 + i0 * bin, 1.0 - (j0 + h) * bin, -1.0 + (i0 + w) * bin, 1.0 - j0 * bin};
      double avg = 0.0;
      ASSERT_EQ(f.ndf.average(fp, r, &avg), RuntimeStatus::kOk);
      EXPECT_NEAR(avg, mean, 1e-5 * mean + 1e-9);
    }
  }
}

TEST(FlakeNdf, FlatMapIsTheIntrinsicGaussianAndIntegratesToOne) {
  Fixture f(reference::testing::constantMap(32, 32, 0.1, -0.2));
  const double sr = reference::kDefaultSigmaR;
  for (double sigma : {0.0, 0.5, 4.0}) {
    const Footprint fp{7.0, 9.0, sigma};
    // Small footprints see the flake lattice: their mass is not 1, but their shape is the Gaussian.
    double mass = 0.0;
    ASSERT_EQ(f.ndf.mass(fp, &mass), RuntimeStatus::kOk);
    if (sigma >= 1.0) {
      EXPECT_NEAR(mass, 1.0, 1e-6);
    }
    const float nx = float(0.1), ny = float(-0.2);  // the normal as the map stores it
    for (SPoint s : {SPoint{0.1, -0.2}, SPoint{0.104, -0.197}, SPoint{0.09, -0.21}}) {
      double v = 0.0;
      ASSERT_EQ(f.ndf.eval(fp, s, &v), RuntimeStatus::kOk);
      v /= mass;
      const double d2 = (s.x - nx) * (s.x - nx) + (s.y - ny) * (s.y - ny);
      const double expected = std::exp(-d2 / (2 * sr * sr)) / (kTwoPi * sr * sr);
      EXPECT_NEAR(v, expected, 1e-5 * expected + 1e-9);
    }
  }
}

TEST(FlakeNdf, PointFootprintIsTheLimitOfSmallOnes) {
  Fixture f(mapOf(bake::MapKind::kBeckmann, 32, 9));
  const Footprint point{10.2, 5.9, 0.0}, tiny{10.2, 5.9, 1e-5};
  std::mt19937_64 rng(3);
  for (SPoint s : probePoints(f, {10.2, 5.9, 1e-5}, rng)) {
    double a = 0.0, b = 0.0;
    ASSERT_EQ(f.ndf.eval(point, s, &a), RuntimeStatus::kOk);
    ASSERT_EQ(f.ndf.eval(tiny, s, &b), RuntimeStatus::kOk);
    EXPECT_NEAR(a, b, 1e-6 * std::max(a, b) + 1e-9);
  }
}

TEST(FlakeNdf, SamplesFollowTheirPdf) {
  Fixture f(mapOf(bake::MapKind::kBeckmann, 64, 21), 1, 32);
  for (double sigma : {0.8, 3.0}) {
    const Footprint fp{40.5, 22.25, sigma};
    double mass = 0.0;
    ASSERT_EQ(f.ndf.mass(fp, &mass), RuntimeStatus::kOk);
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    struct S {
      double sx, sy;
    };
    std::vector<S> samples;
    for (int i = 0; i < 30000; ++i) {
      runtime::NdfSample smp;
      ASSERT_EQ(f.ndf.sample(fp, u(rng), u(rng), &smp), RuntimeStatus::kOk);
      double p = -1.0, e = -1.0;
      ASSERT_EQ(f.ndf.pdf(fp, smp.s, &p), RuntimeStatus::kOk);
      ASSERT_EQ(f.ndf.eval(fp, smp.s, &e), RuntimeStatus::kOk);
      EXPECT_EQ(p, smp.pdf);
      EXPECT_NEAR(p * mass, e, 1e-12 * e);
      samples.push_back({smp.s.x, smp.s.y});
    }
    std::vector<float> img(32 * 32);
    ASSERT_EQ(f.ndf.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
    const std::vector<double> image(img.begin(), img.end());
    const stats::ChiSquareResult r = stats::chiSquareNdfTest(samples, image, 32, mass);
    EXPECT_GT(r.p_value, 0.01) << "sigma " << sigma << ": " << r.message;
  }
}

// The AVX2 kernels (where the processor has them) and the portable ones give the same bits.
TEST(FlakeNdf, KernelsGiveTheSameBits) {
  for (bake::MapKind kind : {bake::MapKind::kBeckmann, bake::MapKind::kScratches, bake::MapKind::kFlakes}) {
    Fixture f(mapOf(kind, 64, 31));
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> pos(0.0, 64.0);
    for (double sigma : {0.0, 0.6, 2.0, 5.0}) {
      for (int trial = 0; trial < 4; ++trial) {
        const reference::Footprint rfp{pos(rng), pos(rng), std::max(sigma, 1e-6)};
        for (const SPoint& s : probePoints(f, rfp, rng)) {
          const Footprint fp{rfp.x, rfp.y, sigma};
          double wide = -1.0, portable = -2.0;
          runtime::usePortableFlakeKernels(false);
          ASSERT_EQ(f.ndf.eval(fp, s, &wide), RuntimeStatus::kOk);
          runtime::usePortableFlakeKernels(true);
          ASSERT_EQ(f.ndf.eval(fp, s, &portable), RuntimeStatus::kOk);
          runtime::usePortableFlakeKernels(false);
          EXPECT_EQ(wide, portable) << "sigma " << sigma;
        }
      }
    }
  }
}

TEST(FlakeNdf, RejectsBadArgumentsAndSources) {
  Fixture f(mapOf(bake::MapKind::kBeckmann, 16, 2));
  double v = 0.0;
  EXPECT_EQ(f.ndf.eval({1, 1, -1.0}, {0, 0}, &v), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(f.ndf.eval({NAN, 1, 1.0}, {0, 0}, &v), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(f.ndf.eval({1, 1, 1.0}, {0, INFINITY}, &v), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(f.ndf.eval({1, 1, 1e5}, {0, 0}, &v), RuntimeStatus::kInvalidArgument);  // beyond the window limit
  runtime::NdfSample smp;
  EXPECT_EQ(f.ndf.sample({1, 1, 1.0}, 1.0, 0.5, &smp), RuntimeStatus::kInvalidArgument);
  FlakeNdf other;
  const auto texels = mapTexels(f.map);
  EXPECT_EQ(other.build(texels, 0, 0.005, 64), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(other.build(texels, 1, 0.0, 64), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(other.build(texels, 1, 0.005, 1), RuntimeStatus::kInvalidArgument);
  EXPECT_FALSE(other.isBuilt());
  EXPECT_EQ(other.eval({1, 1, 1.0}, {0, 0}, &v), RuntimeStatus::kInvalidArgument);
}

}  // namespace
}  // namespace glintbake
