// SPDX-License-Identifier: Apache-2.0
// Tests of the hand-over tensorpack chooses from its levels' errors (cli/tensor_asset.h).
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/cli/tensor_asset.h>
#include <glintbake/runtime/texel_source.h>

#include "../flakes/flakes_asset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace glintbake;

namespace {

bake::tensor::TensorPackLevelReport level(double sigma, double frobenius, double l1, double variation, bool exact) {
  bake::tensor::TensorPackLevelReport l;
  l.sigma = sigma;
  l.relative_error = exact ? 0.0 : frobenius;
  l.l1_error = exact ? 0.0 : l1;
  l.variation = variation;
  l.exact = exact;
  return l;
}

// Three levels (8, 16, 32 texels), the top one exact, the two below compressed with these errors.
bake::tensor::TensorPackReport pyramid(double frobenius, double l1) {
  bake::tensor::TensorPackReport r;
  r.levels = {level(8, frobenius, l1, 0.5, false), level(16, frobenius, l1, 0.4, false), level(32, 0, 0, 0.3, true)};
  return r;
}

}  // namespace

// Compressed levels within every bound answer from twice the finest sigma, as an uncompressed
// pyramid does; levels whose images are off in L1 hand the footprints to the lobes even when their
// Frobenius error is small (one dominant peak kept, the rest of the mass spread), up to the first
// exact level.
TEST(TensorHandover, CompressedLevelsAnswerOnlyWhenTheirImagesAreCloseInL1) {
  const double kSqrt2 = std::sqrt(2.0);
  const bake::ndf::FlakesHandover good = cli::tensorHandover(pyramid(0.05, 0.03), 16);
  EXPECT_EQ(good.lobes_per_tile, 16);
  EXPECT_DOUBLE_EQ(good.lobes_up_to, 8 * kSqrt2);
  EXPECT_DOUBLE_EQ(good.pyramid_from, 16.0);

  const bake::ndf::FlakesHandover off = cli::tensorHandover(pyramid(0.05, 0.3), 16);
  EXPECT_DOUBLE_EQ(off.lobes_up_to, 32.0);
  EXPECT_DOUBLE_EQ(off.pyramid_from, 32 * kSqrt2);

  // Frobenius still counts: a level far off in it does not answer, whatever its L1 error.
  const bake::ndf::FlakesHandover far = cli::tensorHandover(pyramid(0.3, 0.03), 16);
  EXPECT_DOUBLE_EQ(far.lobes_up_to, 32.0);

  // Only the finest level off: the pyramid answers from the second, blended with the lobes over
  // the half octave below twice its sigma.
  bake::tensor::TensorPackReport one = pyramid(0.05, 0.03);
  one.levels[0].l1_error = 0.2;
  const bake::ndf::FlakesHandover h = cli::tensorHandover(one, 16);
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 16 * kSqrt2);
  EXPECT_DOUBLE_EQ(h.pyramid_from, 32.0);

  // A first exact level without the map's flakes to probe: the pyramid answers from sqrt(2) times
  // it, whatever its images' variation.
  bake::tensor::TensorPackReport glints = pyramid(0.05, 0.3);
  glints.levels[2].variation = 0.9;
  const bake::ndf::FlakesHandover unprobed = cli::tensorHandover(glints, 16);
  EXPECT_DOUBLE_EQ(unprobed.lobes_up_to, 32.0);
  EXPECT_DOUBLE_EQ(unprobed.pyramid_from, 32 * kSqrt2);

  // With them, as the probe finds: on a map of sharp flakes 12 texels across (a few dozen glints
  // per footprint) the blend above an exact level of 16 texels is far off and the lobes closer, so
  // they answer up to sqrt(2) times it and the pyramid from twice it.
  glints.levels[1] = level(16, 0, 0, 0.4, true);
  const bake::NormalMap flakes = glintbake::testing::flakesMap(256, 12.0, 15.0, 5);
  std::vector<float> normals;
  for (int y = 0; y < flakes.height; ++y)
    for (int x = 0; x < flakes.width; ++x) normals.insert(normals.end(), flakes.at(x, y), flakes.at(x, y) + 2);
  const runtime::InterleavedTexels texels(flakes.width, flakes.height, true, normals.data(), 2);
  for (size_t l = 0; l < glints.levels.size(); ++l) {
    const bake::ndf::LevelGeometry g =
        bake::ndf::levelGeometry(flakes.width, flakes.height, bake::ndf::PyramidOptions{}, int(l), true);
    glints.levels[l].grid_width = g.grid_width;
    glints.levels[l].grid_height = g.grid_height;
  }
  // The level above (32 texels) is probed next; there the blend is faithful.
  std::vector<bake::ndf::HandoverProbe> probes;
  const bake::ndf::FlakesHandover g = cli::tensorHandover(glints, 16, &texels, 1, 0.005, &probes);
  ASSERT_EQ(probes.size(), 2u);
  ASSERT_TRUE(probes[0].ran);
  EXPECT_DOUBLE_EQ(probes[0].sigma, 16 * kSqrt2);
  EXPECT_TRUE(probes[0].lobesAnswer());
  ASSERT_TRUE(probes[1].ran);
  EXPECT_DOUBLE_EQ(probes[1].sigma, 32 * kSqrt2);
  EXPECT_FALSE(probes[1].lobesAnswer());
  EXPECT_DOUBLE_EQ(g.lobes_up_to, 16 * kSqrt2);
  EXPECT_DOUBLE_EQ(g.pyramid_from, 32.0);

  // Without lobes the flakes hand over to the pyramid at its finest level, faithful or not.
  const bake::ndf::FlakesHandover none = cli::tensorHandover(pyramid(0.05, 0.3), 0);
  EXPECT_EQ(none.lobes_per_tile, 0);
  EXPECT_DOUBLE_EQ(none.flakes_up_to, 8.0);
}
