// SPDX-License-Identifier: Apache-2.0
// LobeNdf (runtime) against the exact flakes: a lobe of one flake is that flake (so level 0, where
// every flake keeps its own lobe, is exact but for the window), clustered levels stay close, a
// flat map gives the intrinsic Gaussian, a rotated map rotates the NDF, samples follow their pdf
// (chi-square) with pdf == eval / mass, and the asset's hand-overs stay consistent.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/container.h>
#include <glintbake/format/numbers.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/lobe_ndf.h>

#include "../../stats/chi_square.h"
#include "../reference/test_maps.h"
#include "../temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace glintbake {
namespace {

using runtime::Footprint;
using runtime::LobeNdf;
using runtime::RuntimeStatus;
using runtime::SPoint;

runtime::InterleavedTexels lobeTexels(const bake::NormalMap& map) {
  return runtime::InterleavedTexels(map.width, map.height, map.wrap == bake::Wrap::kRepeat, map.normals.data(), 3);
}

bake::NormalMap lobeMap(bake::MapKind kind, int size, uint64_t seed) {
  bake::MapParams p;
  p.size = size;
  p.seed = seed;
  return bake::generateMap(kind, p);
}

// Relative L1 distance between two images.
double relativeL1(const std::vector<float>& a, const std::vector<float>& ref) {
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    num += std::fabs(double(a[i]) - double(ref[i]));
    den += std::fabs(double(ref[i]));
  }
  return num / den;
}

struct Pair {
  bake::NormalMap map;
  runtime::FlakeNdf flakes;
  LobeNdf lobes;
  int res;
  Pair(bake::NormalMap m, int lobes_per_tile, int r = 64, int rate = 1) : map(std::move(m)), res(r) {
    const auto texels = lobeTexels(map);
    EXPECT_EQ(flakes.build(texels, rate, reference::kDefaultSigmaR, res), RuntimeStatus::kOk);
    EXPECT_EQ(lobes.build(texels, rate, reference::kDefaultSigmaR, lobes_per_tile, res), RuntimeStatus::kOk);
  }
  double imageError(const Footprint& fp) const {
    std::vector<float> a(size_t(res) * res), b(size_t(res) * res);
    EXPECT_EQ(lobes.image(fp, a.data(), a.size()), RuntimeStatus::kOk);
    EXPECT_EQ(flakes.image(fp, b.data(), b.size()), RuntimeStatus::kOk);
    return relativeL1(a, b);
  }
};

TEST(LobeNdf, UnclusteredLevelIsTheExactFlakesButForTheWindow) {
  // 16 lobes per tile keep every flake of a 4 x 4 tile: the only difference to the exact path is
  // the 3-sigma window (about 1% of the mass).
  for (bake::MapKind kind : {bake::MapKind::kBeckmann, bake::MapKind::kFlakes, bake::MapKind::kScratches}) {
    Pair p(lobeMap(kind, 64, 5), 16);
    for (double sigma : {4.0, 7.0}) {
      ASSERT_EQ(p.lobes.tileFor(sigma), 4);
      const Footprint fp{21.3, 40.8, sigma};
      EXPECT_LT(p.imageError(fp), 0.03) << "kind " << int(kind) << " sigma " << sigma;
      double ml = 0.0, mf = 0.0;
      ASSERT_EQ(p.lobes.mass(fp, &ml), RuntimeStatus::kOk);
      ASSERT_EQ(p.flakes.mass(fp, &mf), RuntimeStatus::kOk);
      EXPECT_NEAR(ml / mf, 1.0, 0.01);
    }
  }
}

// The merging keeps lobes of different orientations apart: k-means on the normal means gave 0.062
// (beckmann) and 0.058 (scratches) here, the greedy reduction 0.040 and 0.013.
TEST(LobeNdf, ClusteredLevelsStayCloseToTheExactFlakes) {
  for (bake::MapKind kind :
       {bake::MapKind::kBeckmann, bake::MapKind::kFlakes, bake::MapKind::kBrushed, bake::MapKind::kScratches}) {
    Pair p(lobeMap(kind, 128, 8), 16);
    for (double sigma : {24.0}) {
      EXPECT_GT(p.lobes.tileFor(sigma), 4);
      const Footprint fp{70.2, 33.9, sigma};
      const double e = p.imageError(fp);
      EXPECT_LT(e, 0.05) << "kind " << int(kind) << " sigma " << sigma;
      // Coarser tiles far from the centre (the cut) keep the footprint's mass.
      double ml = 0.0, mf = 0.0;
      ASSERT_EQ(p.lobes.mass(fp, &ml), RuntimeStatus::kOk);
      ASSERT_EQ(p.flakes.mass(fp, &mf), RuntimeStatus::kOk);
      EXPECT_NEAR(ml / mf, 1.0, 0.01) << "kind " << int(kind);
      std::printf("kind %d sigma %g: relative L1 %.3f\n", int(kind), sigma, e);
    }
  }
}

// From 11.4 texels the single-flake level takes a cut too: the level-1 tiles within sqrt(2) sigma
// of the centre come from the exact flakes' evaluator (pruned by normal), the tiles farther out
// from coarser lobes; the image walks those inner tiles as level-0 lobes instead. Every tile is
// counted once on every path: eval integrates to the mass, the image holds the mass, and the mass
// stays within 1% of the exact flakes', at the map's corners too (repeating and clamped), and at
// two flakes per texel (where the band starts at half the footprint).
TEST(LobeNdf, InnerTilesFromTheExactFlakesCountOnce) {
  struct Case {
    bake::MapKind kind;
    bake::Wrap wrap;
    int rate;
  };
  for (const Case& c :
       {Case{bake::MapKind::kBeckmann, bake::Wrap::kRepeat, 1}, Case{bake::MapKind::kBeckmann, bake::Wrap::kClamp, 1},
        Case{bake::MapKind::kScratches, bake::Wrap::kRepeat, 1}, Case{bake::MapKind::kScratches, bake::Wrap::kClamp, 1},
        Case{bake::MapKind::kScratches, bake::Wrap::kRepeat, 2}}) {
    const bake::MapKind kind = c.kind;
    const bake::Wrap wrap = c.wrap;
    {
      bake::NormalMap map = lobeMap(kind, 96 / c.rate, 31);
      map.wrap = wrap;
      Pair p(std::move(map), 16, 64, c.rate);
      const double r = c.rate;
      for (double sigma : {12.0 / r, 19.0 / r}) {
        for (const Footprint& fp : {Footprint{40.3 / r, 57.6 / r, sigma}, Footprint{2.7 / r, 94.1 / r, sigma}}) {
          ASSERT_EQ(p.lobes.tileFor(sigma), 4);
          double mass = 0.0, mf = 0.0;
          ASSERT_EQ(p.lobes.mass(fp, &mass), RuntimeStatus::kOk);
          ASSERT_EQ(p.flakes.mass(fp, &mf), RuntimeStatus::kOk);
          EXPECT_NEAR(mass / mf, 1.0, 0.01);
          // Midpoint rule on a 256^2 grid: spacing 0.0078 against lobes of std >= sigma_r = 0.005
          // integrates a Gaussian to about 1e-4.
          const int n = 256;
          const double h = 2.0 / n;
          double integral = 0.0;
          for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
              double v = 0.0;
              ASSERT_EQ(p.lobes.eval(fp, {-1.0 + (i + 0.5) * h, -1.0 + (j + 0.5) * h}, &v), RuntimeStatus::kOk);
              integral += v * h * h;
            }
          }
          std::vector<float> img(size_t(64) * 64);
          ASSERT_EQ(p.lobes.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
          double held = 0.0;
          for (float b : img) held += double(b) * (2.0 / 64) * (2.0 / 64);
          const std::string where = "kind " + std::to_string(int(kind)) + " wrap " + std::to_string(int(wrap)) +
                                    " rate " + std::to_string(c.rate) + " sigma " + std::to_string(sigma) + " x " +
                                    std::to_string(fp.x);
          EXPECT_NEAR(integral / mass, 1.0, 2e-3) << where;
          EXPECT_NEAR(held / mass, 1.0, 2e-3) << where;
        }
      }
    }
  }
}

TEST(LobeNdf, FlatMapIsTheIntrinsicGaussian) {
  const bake::NormalMap map = reference::testing::constantMap(64, 64, 0.1, -0.2);
  const auto texels = lobeTexels(map);
  LobeNdf ndf;
  ASSERT_EQ(ndf.build(texels, 1, reference::kDefaultSigmaR, 8, 64), RuntimeStatus::kOk);
  const double sr = reference::kDefaultSigmaR;
  for (double sigma : {6.0, 15.0, 40.0}) {
    const Footprint fp{17.0, 9.0, sigma};
    double mass = 0.0;
    ASSERT_EQ(ndf.mass(fp, &mass), RuntimeStatus::kOk);
    EXPECT_NEAR(mass, 1.0, 2e-3) << sigma;
    const float nx = float(0.1), ny = float(-0.2);
    for (SPoint s : {SPoint{0.1, -0.2}, SPoint{0.104, -0.197}, SPoint{0.09, -0.21}}) {
      double v = 0.0;
      ASSERT_EQ(ndf.eval(fp, s, &v), RuntimeStatus::kOk);
      const double d2 = (s.x - nx) * (s.x - nx) + (s.y - ny) * (s.y - ny);
      const double expected = std::exp(-d2 / (2 * sr * sr)) / (kTwoPi * sr * sr);
      EXPECT_NEAR(v / mass, expected, 1e-3 * expected + 1e-6);
    }
  }
}

TEST(LobeNdf, RotatedMapRotatesTheNdf) {
  // Rotating the map by 90 degrees (texel (x, y) -> (h - 1 - y, x), normal (nx, ny) -> (-ny, nx))
  // rotates the NDF at the rotated footprint centre.
  const bake::NormalMap map = lobeMap(bake::MapKind::kBeckmann, 64, 13);
  bake::NormalMap rot = map;
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      const float* n = map.normals.data() + (size_t(y) * map.width + x) * 3;
      float* r = rot.normals.data() + (size_t(x) * map.width + (map.height - 1 - y)) * 3;
      r[0] = -n[1];
      r[1] = n[0];
      r[2] = n[2];
    }
  }
  const auto ta = lobeTexels(map), tb = lobeTexels(rot);
  LobeNdf a, b;
  ASSERT_EQ(a.build(ta, 1, reference::kDefaultSigmaR, 16, 64), RuntimeStatus::kOk);
  ASSERT_EQ(b.build(tb, 1, reference::kDefaultSigmaR, 16, 64), RuntimeStatus::kOk);
  const double ux = 20.0, uy = 36.0;  // a multiple of the tile side: the same tiles after rotation
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> any(-0.3, 0.3);
  double num = 0.0, den = 0.0;
  for (int i = 0; i < 200; ++i) {
    const SPoint s{any(rng), any(rng)};
    double va = 0.0, vb = 0.0;
    ASSERT_EQ(a.eval({ux, uy, 6.0}, s, &va), RuntimeStatus::kOk);
    ASSERT_EQ(b.eval({64.0 - uy, ux, 6.0}, {-s.y, s.x}, &vb), RuntimeStatus::kOk);
    num += std::fabs(va - vb);
    den += va;
  }
  EXPECT_LT(num / den, 1e-3);
}

TEST(LobeNdf, SamplesFollowTheirPdf) {
  // 6: the exact flakes of level 0; 14: their inner tiles with coarser lobes farther out; 30: a
  // clustered level with coarser tiles far out.
  Pair p(lobeMap(bake::MapKind::kBeckmann, 128, 21), 16, 32);
  for (double sigma : {6.0, 14.0, 30.0}) {
    const Footprint fp{40.5, 22.25, sigma};
    double mass = 0.0;
    ASSERT_EQ(p.lobes.mass(fp, &mass), RuntimeStatus::kOk);
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    struct S {
      double sx, sy;
    };
    std::vector<S> samples;
    for (int i = 0; i < 20000; ++i) {
      runtime::NdfSample smp;
      ASSERT_EQ(p.lobes.sample(fp, u(rng), u(rng), &smp), RuntimeStatus::kOk);
      double pdf = -1.0, e = -1.0;
      ASSERT_EQ(p.lobes.pdf(fp, smp.s, &pdf), RuntimeStatus::kOk);
      ASSERT_EQ(p.lobes.eval(fp, smp.s, &e), RuntimeStatus::kOk);
      EXPECT_EQ(pdf, smp.pdf);
      EXPECT_NEAR(pdf * mass, e, 1e-12 * e);
      samples.push_back({smp.s.x, smp.s.y});
    }
    std::vector<float> img(32 * 32);
    ASSERT_EQ(p.lobes.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
    const std::vector<double> image(img.begin(), img.end());
    const stats::ChiSquareResult r = stats::chiSquareNdfTest(samples, image, 32, mass);
    EXPECT_GT(r.p_value, 0.01) << "sigma " << sigma << ": " << r.message;
  }
}

// At 16 lobes per tile the finest level (every flake its own lobe, a kilobyte a tile of 16) is not
// stored: its tiles are made from the normals when needed. With fewer lobes it is grouped and kept.
TEST(LobeNdf, FinestLevelIsMadeNotStoredAtSixteenLobes) {
  const bake::NormalMap map = lobeMap(bake::MapKind::kFlakes, 128, 5);
  const auto texels = lobeTexels(map);
  const double flakes = 128.0 * 128.0;
  LobeNdf made, stored;
  EXPECT_EQ(made.memoryBytes(), 0u);
  ASSERT_EQ(made.build(texels, 1, 0.005, 16, 32), RuntimeStatus::kOk);
  ASSERT_EQ(stored.build(texels, 1, 0.005, 15, 32), RuntimeStatus::kOk);
  // Levels above the finest: 1 + 1/4 + ... blocks of 960 bytes per 64 flakes; normals 8 bytes.
  EXPECT_LT(double(made.memoryBytes()) / flakes, 30.0);
  EXPECT_GT(double(stored.memoryBytes()) / flakes, 70.0);
  // The made tiles answer images and averages (which walk them at 11.4-22.9 texels) as the flakes.
  runtime::FlakeNdf exact;
  ASSERT_EQ(exact.build(texels, 1, 0.005, 32), RuntimeStatus::kOk);
  std::vector<float> a(32 * 32), b(32 * 32);
  for (double sigma : {12.0, 16.0, 20.0}) {
    const Footprint fp{60.3, 70.9, sigma};
    ASSERT_EQ(made.image(fp, a.data(), a.size()), RuntimeStatus::kOk);
    ASSERT_EQ(exact.image(fp, b.data(), b.size()), RuntimeStatus::kOk);
    EXPECT_LT(relativeL1(a, b), 0.02) << sigma;  // the 3-sigma window against the 6-sigma one
  }
}

TEST(LobeNdf, AverageIsTheMeanOfTheImageBins) {
  Pair p(lobeMap(bake::MapKind::kFlakes, 64, 3), 8, 32);
  const Footprint fp{30.0, 12.5, 9.0};
  std::vector<float> img(32 * 32);
  ASSERT_EQ(p.lobes.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
  const double bin = 2.0 / 32;
  for (int j = 8; j < 24; j += 3) {
    for (int i = 8; i < 24; i += 3) {
      const runtime::SRect r{-1.0 + i * bin, 1.0 - (j + 1) * bin, -1.0 + (i + 1) * bin, 1.0 - j * bin};
      double avg = 0.0;
      ASSERT_EQ(p.lobes.average(fp, r, &avg), RuntimeStatus::kOk);
      EXPECT_NEAR(avg, img[size_t(j) * 32 + i], 1e-4 * avg + 1e-6);
    }
  }
}

// Point evals (not only images) stay close to the exact flakes: on level 0 (every flake its own
// lobe, evaluated by the exact flakes' evaluator with the 3-sigma window) and on a clustered level.
TEST(LobeNdf, EvalStaysCloseToTheExactFlakes) {
  for (bake::MapKind kind : {bake::MapKind::kBeckmann, bake::MapKind::kScratches, bake::MapKind::kFlakes}) {
    Pair p(lobeMap(kind, 128, 12), 16);
    for (double sigma : {6.0, 12.0, 24.0}) {
      const Footprint fp{50.7, 81.2, sigma};
      double num = 0.0, den = 0.0;
      for (int j = 0; j < 40; ++j) {
        for (int i = 0; i < 40; ++i) {
          const SPoint s{-1.0 + (i + 0.5) / 20.0, -1.0 + (j + 0.5) / 20.0};
          if (s.x * s.x + s.y * s.y > 1.0) continue;
          double a = 0.0, b = 0.0;
          ASSERT_EQ(p.lobes.eval(fp, s, &a), RuntimeStatus::kOk);
          ASSERT_EQ(p.flakes.eval(fp, s, &b), RuntimeStatus::kOk);
          num += std::fabs(a - b);
          den += b;
        }
      }
      EXPECT_LT(num / den, sigma < 20.0 ? 0.03 : 0.4) << "kind " << int(kind) << " sigma " << sigma;
    }
  }
}

// The AVX2 kernels (where the processor has them) and the portable ones give the same bits.
TEST(LobeNdf, KernelsGiveTheSameBits) {
  Pair p(lobeMap(bake::MapKind::kBeckmann, 128, 13), 16);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> pos(0.0, 128.0), any(-0.6, 0.6);
  for (double sigma : {6.0, 14.0, 30.0}) {
    for (int trial = 0; trial < 24; ++trial) {
      const Footprint fp{pos(rng), pos(rng), sigma};
      const SPoint s{any(rng), any(rng)};
      double wide = -1.0, portable = -2.0;
      runtime::usePortableFlakeKernels(false);
      ASSERT_EQ(p.lobes.eval(fp, s, &wide), RuntimeStatus::kOk);
      runtime::usePortableFlakeKernels(true);
      ASSERT_EQ(p.lobes.eval(fp, s, &portable), RuntimeStatus::kOk);
      runtime::usePortableFlakeKernels(false);
      EXPECT_EQ(wide, portable) << "sigma " << sigma;
    }
  }
}

// The reduction's merge costs run four wide under AVX2 and two wide otherwise: the same hierarchy.
TEST(LobeNdf, BuildGivesTheSameBitsWithEitherKernel) {
  const bake::NormalMap map = lobeMap(bake::MapKind::kScratches, 128, 21);
  const auto texels = lobeTexels(map);
  LobeNdf wide, portable;
  runtime::usePortableFlakeKernels(false);
  ASSERT_EQ(wide.build(texels, 1, reference::kDefaultSigmaR, 16, 64), RuntimeStatus::kOk);
  wide.prepare();
  runtime::usePortableFlakeKernels(true);
  ASSERT_EQ(portable.build(texels, 1, reference::kDefaultSigmaR, 16, 64), RuntimeStatus::kOk);
  portable.prepare();
  std::vector<float> a(64 * 64), b(64 * 64);
  for (double sigma : {14.0, 30.0, 60.0}) {
    const Footprint fp{41.3, 87.9, sigma};
    ASSERT_EQ(wide.image(fp, a.data(), a.size()), RuntimeStatus::kOk);
    ASSERT_EQ(portable.image(fp, b.data(), b.size()), RuntimeStatus::kOk);
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << "sigma " << sigma;
  }
  runtime::usePortableFlakeKernels(false);
}

TEST(LobeNdf, DeterministicAndRejectsBadArguments) {
  const bake::NormalMap map = lobeMap(bake::MapKind::kScratches, 64, 4);
  const auto texels = lobeTexels(map);
  LobeNdf a, b;
  ASSERT_EQ(a.build(texels, 1, reference::kDefaultSigmaR, 8, 32), RuntimeStatus::kOk);
  ASSERT_EQ(b.build(texels, 1, reference::kDefaultSigmaR, 8, 32), RuntimeStatus::kOk);
  for (double sigma : {5.0, 12.0, 30.0}) {
    double va = 0.0, vb = 0.0;
    ASSERT_EQ(a.eval({3.0, 60.0, sigma}, {0.01, 0.02}, &va), RuntimeStatus::kOk);
    ASSERT_EQ(b.eval({3.0, 60.0, sigma}, {0.01, 0.02}, &vb), RuntimeStatus::kOk);
    EXPECT_EQ(va, vb);
  }
  double v = 0.0;
  EXPECT_EQ(a.eval({1.0, 1.0, std::nan("")}, {0, 0}, &v), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(a.eval({1.0, 1.0, 4.0}, {std::nan(""), 0}, &v), RuntimeStatus::kInvalidArgument);
  const double too_large = a.footprintRange().clustered_max_sigma * 1.5;
  EXPECT_EQ(a.eval({1.0, 1.0, too_large}, {0, 0}, &v), RuntimeStatus::kInvalidArgument);
  LobeNdf c;
  EXPECT_EQ(c.build(texels, 1, reference::kDefaultSigmaR, 0, 32), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(c.build(texels, 1, reference::kDefaultSigmaR, 17, 32), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(c.build(texels, 0, reference::kDefaultSigmaR, 8, 32), RuntimeStatus::kInvalidArgument);
  std::vector<float> bad = map.normals;
  bad[7] = std::nanf("");
  const runtime::InterleavedTexels bad_texels(map.width, map.height, true, bad.data(), 3);
  EXPECT_EQ(c.build(bad_texels, 1, reference::kDefaultSigmaR, 8, 32), RuntimeStatus::kInvalidArgument);
  EXPECT_FALSE(c.isBuilt());
}

}  // namespace
}  // namespace glintbake
