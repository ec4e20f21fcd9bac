// SPDX-License-Identifier: Apache-2.0
// Chi-square tests of the reference P-NDF sampler (reference::samplePndf) against the reference
// bin-averaged NDF image (reference::binAveragedImage): the two are written independently (mixture
// sampling vs exact Gaussian rectangle integrals), so agreement checks both. Flat and rough
// procedural maps, footprints from sub-texel to wider than the map, repeat and clamp wrapping.
// The power tests show that a sampler of a slightly different P-NDF is rejected.
#include "chi_square.h"

#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/reference/flakes.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/reference/sampling.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::reference {
namespace {

constexpr double kPassAlpha = 0.01;    // a correct sampler passes with p above this
constexpr double kRejectAlpha = 1e-6;  // a wrong sampler must fall below this
constexpr size_t kSamples = 200000;
constexpr uint64_t kSeed = 20161;

bake::NormalMap proceduralMap(bake::MapKind kind, int size, uint64_t seed, double alpha = 0.3) {
  bake::MapParams params;
  params.size = size;
  params.seed = seed;
  params.alpha = alpha;
  return bake::generateMap(kind, params);
}

struct Case {
  std::string name;
  double x, y, sigma;  // footprint, texels
  double sigma_r;
  int res;
};

// Samples the footprint's P-NDF (optionally from a different footprint or roughness: the
// power tests) and tests them against the bin-averaged image of the footprint under test.
stats::ChiSquareResult testFootprint(const FlakeSet& flakes, const Case& c, const Footprint* sample_fp = nullptr,
                                     double sample_sigma_r = 0.0) {
  const Footprint fp{c.x, c.y, c.sigma};
  const Footprint draw_fp = sample_fp != nullptr ? *sample_fp : fp;
  const double draw_sigma_r = sample_sigma_r > 0.0 ? sample_sigma_r : c.sigma_r;
  const std::vector<PndfSample> samples = samplePndf(flakes, draw_fp, draw_sigma_r, kSamples, kSeed);
  EXPECT_EQ(samples.size(), kSamples) << c.name;
  const std::vector<double> image = binAveragedImage(flakes, fp, c.sigma_r, c.res);
  return stats::chiSquareNdfTest(samples, image, c.res, footprintWeight(flakes, fp));
}

void expectPasses(const FlakeSet& flakes, const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    const stats::ChiSquareResult r = testFootprint(flakes, c);
    std::printf("  %s: %s\n", c.name.c_str(), r.message.c_str());
    EXPECT_TRUE(r.passed(kPassAlpha)) << c.name << ": " << r.message;
    // Enough cells that the test means something.
    EXPECT_GE(r.cells, 4) << c.name << ": " << r.message;
  }
}

TEST(ReferenceSamplingChiSquare, FlatMap) {
  // Flat: D = N(s; 0, sigma_r^2 I). A wide sigma_r spreads over many bins; the default one
  // concentrates on the four bins around s = 0 (bin edges at 0 for even res).
  const FlakeSet flakes = buildFlakes(proceduralMap(bake::MapKind::kFlat, 16, 1), 1);
  expectPasses(flakes, {{"flat, sigma_r 0.05", 8.0, 8.0, 2.0, 0.05, 64},
                        {"flat, sigma_r 0.2", 3.5, 12.2, 1.0, 0.2, 32},
                        {"flat, default sigma_r", 0.3, 15.9, 4.0, kDefaultSigmaR, 64}});
}

TEST(ReferenceSamplingChiSquare, BeckmannMap) {
  const FlakeSet flakes = buildFlakes(proceduralMap(bake::MapKind::kBeckmann, 32, 7), 1);
  expectPasses(flakes, {{"beckmann, sigma 0.5", 10.3, 20.7, 0.5, 0.01, 64},
                        {"beckmann, sigma 2", 17.0, 5.2, 2.0, kDefaultSigmaR, 64},
                        {"beckmann, sigma 6 across the edge", 0.4, 31.1, 6.0, 0.01, 32},
                        {"beckmann, sigma 20 (wider than the map)", 16.0, 16.0, 20.0, 0.02, 32}});
}

TEST(ReferenceSamplingChiSquare, RoughAndDiscontinuousMaps) {
  // Strong slopes (alpha 0.8 reaches the rim of the s-plane), sub-texel flakes, and flake maps
  // whose cell borders give large Jacobians.
  const FlakeSet rough = buildFlakes(proceduralMap(bake::MapKind::kBeckmann, 24, 3, 0.8), 2);
  expectPasses(rough, {{"beckmann 0.8 rate 2, sigma 1.5", 12.0, 7.3, 1.5, 0.02, 32},
                       {"beckmann 0.8 rate 2, sigma 4", 3.1, 3.9, 4.0, 0.01, 64}});
  const FlakeSet cells = buildFlakes(proceduralMap(bake::MapKind::kFlakes, 32, 11), 1);
  expectPasses(cells, {{"flakes, sigma 3", 9.7, 14.2, 3.0, 0.01, 64}});
  const FlakeSet scratches = buildFlakes(proceduralMap(bake::MapKind::kScratches, 48, 5), 1);
  expectPasses(scratches, {{"scratches, sigma 5", 24.0, 24.0, 5.0, 0.01, 32}});
}

TEST(ReferenceSamplingChiSquare, ClampedMapCorner) {
  // With wrap=clamp a footprint on the corner sees about a quarter of its flakes: the sampler
  // normalises by the smaller total weight.
  bake::NormalMap map = proceduralMap(bake::MapKind::kBeckmann, 32, 9);
  map.wrap = bake::Wrap::kClamp;
  const FlakeSet flakes = buildFlakes(map, 1);
  const Footprint corner{0.0, 0.0, 4.0};
  EXPECT_LT(footprintWeight(flakes, corner), 0.4);
  expectPasses(flakes, {{"clamp corner, sigma 4", 0.0, 0.0, 4.0, 0.01, 64}});
}

TEST(ReferenceSamplingChiSquare, RejectsShiftedFootprintCentre) {
  // Samples of a footprint a quarter texel away from the one the image describes.
  const FlakeSet flakes = buildFlakes(proceduralMap(bake::MapKind::kBeckmann, 32, 7), 1);
  const Case c{"beckmann, sigma 2", 17.0, 5.2, 2.0, kDefaultSigmaR, 64};
  const Footprint shifted{c.x + 0.25, c.y, c.sigma};
  const stats::ChiSquareResult r = testFootprint(flakes, c, &shifted);
  std::printf("  %s: %s\n", c.name.c_str(), r.message.c_str());
  EXPECT_LT(r.p_value, kRejectAlpha) << r.message;
}

TEST(ReferenceSamplingChiSquare, RejectsWrongFootprintWidth) {
  const FlakeSet flakes = buildFlakes(proceduralMap(bake::MapKind::kBeckmann, 32, 7), 1);
  const Case c{"beckmann, sigma 4", 11.0, 19.0, 4.0, 0.01, 32};
  const Footprint wider{c.x, c.y, 4.4};
  const stats::ChiSquareResult r = testFootprint(flakes, c, &wider);
  std::printf("  %s: %s\n", c.name.c_str(), r.message.c_str());
  EXPECT_LT(r.p_value, kRejectAlpha) << r.message;
}

TEST(ReferenceSamplingChiSquare, RejectsWrongIntrinsicRoughness) {
  // sigma_r 0.052 sampled where 0.05 is described, on a flat map (a pure Gaussian).
  const FlakeSet flakes = buildFlakes(proceduralMap(bake::MapKind::kFlat, 16, 1), 1);
  const Case c{"flat, sigma_r 0.05", 8.0, 8.0, 2.0, 0.05, 64};
  const stats::ChiSquareResult r = testFootprint(flakes, c, nullptr, 0.052);
  std::printf("  %s: %s\n", c.name.c_str(), r.message.c_str());
  EXPECT_LT(r.p_value, kRejectAlpha) << r.message;
}

}  // namespace
}  // namespace glintbake::reference
