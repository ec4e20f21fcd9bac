// SPDX-License-Identifier: Apache-2.0
// Roughness mips: a flat map keeps alpha_micro at every level, a bumpy map gets rougher at coarser
// levels, the bake is deterministic, and the EXR holds every mip level.
#include <glintbake/bake/ltc/roughness.h>
#include <glintbake/format/numbers.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include "../temp_dir.h"

namespace glintbake::bake::ltc {
namespace {

NormalMap makeMap(int width, int height, double slope) {
  std::vector<float> pixels(size_t(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      // Two crossed sinusoidal ridges of period 8 texels.
      const double sx = slope * std::sin(kTwoPi * (x + 0.5) / 8.0);
      const double sy = slope * std::cos(kTwoPi * (y + 0.5) / 8.0);
      const double inv = 1.0 / std::sqrt(1.0 + sx * sx + sy * sy);
      float* p = &pixels[(size_t(y) * width + x) * 3];
      p[0] = float(-sx * inv), p[1] = float(-sy * inv), p[2] = float(inv);
    }
  }
  IngestReport report;
  auto map = normalMapFromPixels(width, height, 3, pixels.data(), IngestOptions{}, &report);
  EXPECT_TRUE(map.ok());
  return map.value();
}

TEST(Roughness, FlatMapKeepsAlphaMicroAtEveryLevel) {
  RoughnessOptions options;
  options.alpha_micro = 0.25;
  const auto levels = bakeRoughness(makeMap(37, 20, 0.0), options).value();
  ASSERT_EQ(levels.size(), 7u);  // 37x20, 19x10, 10x5, 5x3, 3x2, 2x1, 1x1
  EXPECT_EQ(levels[1].width, 19);
  EXPECT_EQ(levels[1].height, 10);
  for (const auto& level : levels)
    for (float alpha : level.alpha) EXPECT_NEAR(alpha, 0.25f, 1e-6f);
}

TEST(Roughness, BumpyMapIsRougherAtCoarserLevels) {
  RoughnessOptions options;
  options.alpha_micro = 0.1;
  const auto levels = bakeRoughness(makeMap(64, 64, 0.6), options).value();
  auto mean = [](const RoughnessLevel& level) {
    double sum = 0.0;
    for (float a : level.alpha) sum += a;
    return sum / double(level.alpha.size());
  };
  EXPECT_NEAR(mean(levels[0]), 0.1, 1e-6);
  for (size_t i = 1; i < 4; ++i) EXPECT_GT(mean(levels[i]), mean(levels[i - 1]) + 1e-3) << "level " << i;
  // Exact inversion and the rational fit agree closely.
  options.exact_meso = true;
  const auto exact = bakeRoughness(makeMap(64, 64, 0.6), options).value();
  EXPECT_NEAR(mean(exact[3]), mean(levels[3]), 2e-3);
}

TEST(Roughness, DeterministicAndWritesMipmappedExr) {
  RoughnessOptions options;
  options.alpha_micro = 0.2;
  const NormalMap map = makeMap(48, 32, 0.4);
  std::vector<RoughnessLevel> one, two;
  tbb::task_arena(1).execute([&] { one = bakeRoughness(map, options).value(); });
  tbb::task_arena(2).execute([&] { two = bakeRoughness(map, options).value(); });
  ASSERT_EQ(one.size(), two.size());
  for (size_t i = 0; i < one.size(); ++i) EXPECT_EQ(one[i].alpha, two[i].alpha);

  const std::string path = glintbake::testing::processTempDir() + "ltc_rough.exr";
  const BakeStatus written = writeRoughnessExr(one, path);
  ASSERT_TRUE(written.ok()) << written.error().message;
  auto input = OIIO::ImageInput::open(path);
  ASSERT_TRUE(input);
  int levels = 0;
  while (input->seek_subimage(0, levels)) {
    const OIIO::ImageSpec& spec = input->spec();
    EXPECT_EQ(spec.width, one[size_t(levels)].width);
    EXPECT_EQ(spec.height, one[size_t(levels)].height);
    std::vector<float> data(size_t(spec.width) * spec.height);
    ASSERT_TRUE(input->read_image(0, levels, 0, 1, OIIO::TypeDesc::FLOAT, data.data()));
    EXPECT_EQ(data, one[size_t(levels)].alpha);
    ++levels;
  }
  EXPECT_EQ(levels, int(one.size()));
  input->close();
  std::remove(path.c_str());
  EXPECT_FALSE(bakeRoughness(map, RoughnessOptions{1.5}).ok());
}

}  // namespace
}  // namespace glintbake::bake::ltc
