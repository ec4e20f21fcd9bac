// SPDX-License-Identifier: Apache-2.0
// The runtime reads the frozen 1.0 container of every kind it knows and answers from the frozen
// records exactly (frozen_kinds.h).
#include <glintbake/runtime/glitter_ndf.h>
#include <glintbake/runtime/tiny_example_ndf.h>

#include <glintbake/runtime/ltc.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/tensor_ndf.h>
#include <glintbake/runtime/wang_ndf.h>
#include <cmath>

#include "frozen_kinds.h"

#include <gtest/gtest.h>

namespace glintbake::runtime {
namespace {

std::string frozenPath(const char* name) { return std::string(GLINTBAKE_TEST_DATA_DIR) + "/" + name; }

// The glitter surface is procedural: the frozen record and table must keep producing the same
// facets, so the answers of the model (hashes, draws, split rule) are pinned here.
TEST(FrozenRuntimeV1_0, Glitter) {
  GlitterNdf glitter;
  ASSERT_EQ(glitter.open(frozenPath("v1_0_glitter.gbk").c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(glitter.resolution(), 8);
  EXPECT_EQ(glitter.mapSize().width, 16);
  const format::GlitterUvRegion all = format::GlitterUvRegion::box(0.5, 0.5, 1.0, 1.0);
  format::GlitterCountOptions exact;
  exact.early_stop = false;
  EXPECT_EQ(
      format::glitterCount(glitter.surface(), glitter.shape(), all, format::GlitterDirRegion::all(), exact, nullptr),
      1000.0);
  const double quadrant = format::glitterCount(glitter.surface(), glitter.shape(), all,
                                               format::GlitterDirRegion::rect(0.0, 0.0, 1.0, 1.0), exact, nullptr);
  const double box =
      format::glitterCount(glitter.surface(), glitter.shape(), format::GlitterUvRegion::box(0.3, 0.6, 0.25, 0.25),
                           format::GlitterDirRegion::all(), exact, nullptr);
  EXPECT_EQ(quadrant, 229.0);
  EXPECT_EQ(box, 55.0);
  double mass = 0.0;
  ASSERT_EQ(glitter.mass(Footprint{5.0, 9.0, 2.0}, &mass), RuntimeStatus::kOk);
  EXPECT_NEAR(mass, 0.9799817112940431, 1e-12);
}

// The wang-tiles container: its grid (hash, tile choice) and its sums over the covered tiles.
TEST(FrozenRuntimeV1_0, WangTiles) {
  std::unique_ptr<NdfSource> src;
  ASSERT_EQ(openNdfAsset(frozenPath("v1_0_wang_tiles.gbk").c_str(), &src), RuntimeStatus::kOk);
  ASSERT_EQ(src->kind(), format::AssetKind::kWangTiles);
  EXPECT_EQ(src->resolution(), 4);
  const auto& wang = static_cast<const WangNdf&>(*src);
  EXPECT_EQ(wang.cellTile(-5, 7), 10u);
  EXPECT_EQ(wang.cellTile(1000000, -3), 2u);
  // A footprint whose window meets 3 x 3 cells and one at a grid vertex meeting 2 x 2: each tile's
  // uniform image (0.25) once per covered tile.
  double v = 0.0;
  ASSERT_EQ(src->eval({4.0, 4.0, 1.0}, {0.1, 0.1}, &v), RuntimeStatus::kOk);
  EXPECT_EQ(v, 2.25);
  ASSERT_EQ(src->eval({8.0, 16.0, 1.0}, {0.1, 0.1}, &v), RuntimeStatus::kOk);
  EXPECT_EQ(v, 1.0);
  // The flakes of small footprints.
  double m = 0.0;
  ASSERT_EQ(src->mass({4.0, 4.0, 0.3}, &m), RuntimeStatus::kOk);
  EXPECT_NEAR(m, 0.98335298046632591, 1e-12);
}

TEST(FrozenRuntimeV1_0, NdfPyramid) {
  NdfPyramid pyramid;
  ASSERT_EQ(pyramid.open(frozenPath("v1_0_ndf_pyramid.gbk").c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(pyramid.resolution(), 4);
  EXPECT_EQ(pyramid.levelCount(), 2);
  // A footprint on centre (1, 0) of level 0 reads that centre's image: bin (2, 1) holds s in
  // [0, 0.5] x [0, 0.5].
  double value = 0.0;
  ASSERT_EQ(pyramid.eval(Footprint{6.0, 2.0, 2.0}, SPoint{0.25, 0.25}, &value), RuntimeStatus::kOk);
  EXPECT_EQ(value, double(format::frozen::pyramidBin(0, 1, 2, 1)));
  // Above the top level: level 1's single centre.
  ASSERT_EQ(pyramid.eval(Footprint{3.0, 5.0, 100.0}, SPoint{-0.75, 0.75}, &value), RuntimeStatus::kOk);
  EXPECT_DOUBLE_EQ(value, double(format::frozen::pyramidBin(1, 0, 0, 0)));
}

TEST(FrozenRuntimeV1_0, TensorNdf) {
  TensorNdf tensor;
  ASSERT_EQ(tensor.open(frozenPath("v1_0_tensor_ndf.gbk").c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(tensor.resolution(), 4);
  EXPECT_EQ(tensor.groupCount(), 1);
  EXPECT_EQ(tensor.blocksKept(), 2u);
  using format::frozen::kTensorA;
  using format::frozen::kTensorB;
  using format::frozen::kTensorC;
  double value = 0.0;
  // Bin (1, 0) of block 0 (row 0): A(1) B(0) C(0).
  ASSERT_EQ(tensor.eval(Footprint{8.0, 8.0, 8.0}, SPoint{-0.25, 0.75}, &value), RuntimeStatus::kOk);
  EXPECT_EQ(value, double(kTensorA[1] * kTensorB[0] * kTensorC[0]));
  // Bin (0, 1) of block 3 (row 1): image bin (2, 3).
  ASSERT_EQ(tensor.eval(Footprint{8.0, 8.0, 8.0}, SPoint{0.25, -0.75}, &value), RuntimeStatus::kOk);
  EXPECT_EQ(value, double(kTensorA[0] * kTensorB[1] * kTensorC[1]));
  // A dropped block reads 0.
  ASSERT_EQ(tensor.eval(Footprint{8.0, 8.0, 8.0}, SPoint{0.75, 0.75}, &value), RuntimeStatus::kOk);
  EXPECT_EQ(value, 0.0);
}

TEST(FrozenRuntimeV1_0, LtcTable) {
  LtcTable table;
  ASSERT_EQ(table.open(frozenPath("v1_0_ltc_table.gbk").c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(table.size(), 2);
}

// The frozen tiny example: a footprint much wider than the example answers from the top tile alone.
TEST(FrozenRuntimeV1_0, TinyExample) {
  TinyExampleNdf tiny;
  ASSERT_EQ(tiny.open(frozenPath("v1_0_tiny_example.gbk").c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(tiny.resolution(), 4);
  EXPECT_EQ(tiny.mapSize().width, 4);
  EXPECT_TRUE(tiny.hasFlakes());
  double v = 0.0;
  ASSERT_EQ(tiny.eval(Footprint{1.0, 2.0, 100.0}, SPoint{-0.25, 0.25}, &v), RuntimeStatus::kOk);
  EXPECT_DOUBLE_EQ(v, 0.125 * 6 + 0.5);
  ASSERT_EQ(tiny.eval(Footprint{1.0, 2.0, 100.0}, SPoint{0.75, -0.75}, &v), RuntimeStatus::kOk);
  EXPECT_EQ(v, 0.0);
}

// Levels stored as binary16 (flag half): the runtime widens them to the float32 values of the
// version 1 asset.
TEST(FrozenRuntimeV1_0, TinyExampleHalf) {
  TinyExampleNdf tiny;
  ASSERT_EQ(tiny.open(frozenPath("v1_0_tiny_example_half.gbk").c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(tiny.record().flags, 4u);
  double v = 0.0;
  ASSERT_EQ(tiny.eval(Footprint{1.0, 2.0, 100.0}, SPoint{-0.25, 0.25}, &v), RuntimeStatus::kOk);
  EXPECT_DOUBLE_EQ(v, 0.125 * 6 + 0.5);
}

// Record version 2 (layout image, overlaps): the runtime reads the layout and answers on it.
TEST(FrozenRuntimeV1_0, TinyExampleVersion2) {
  TinyExampleNdf tiny;
  ASSERT_EQ(tiny.open(frozenPath("v1_0_tiny_example_v2.gbk").c_str()), RuntimeStatus::kOk);
  EXPECT_TRUE(tiny.hasFlakes());  // the plane flakes
  EXPECT_FALSE(tiny.hasGridFlakes());
  const format::TinyLayout* layout = tiny.layout();
  ASSERT_TRUE(layout != nullptr);
  if (layout == nullptr) return;
  EXPECT_EQ(layout->width, 2u);
  EXPECT_EQ(layout->channels, 2u);
  EXPECT_EQ(layout->values[1], 0.5f);
  double mass = 0.0;
  ASSERT_EQ(tiny.mass(Footprint{3.0, -5.0, 6.0}, &mass), RuntimeStatus::kOk);
  EXPECT_GT(mass, 0.0);
  EXPECT_TRUE(std::isfinite(mass));
  int64_t examples = 0, tiles = 0;
  ASSERT_EQ(tiny.traversalCount(Footprint{3.0, -5.0, 6.0}, &examples, &tiles), RuntimeStatus::kOk);
  EXPECT_GT(examples, 0);
}

}  // namespace
}  // namespace glintbake::runtime
