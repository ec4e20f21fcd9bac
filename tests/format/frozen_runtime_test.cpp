// SPDX-License-Identifier: Apache-2.0
// The runtime reads the frozen 1.0 container of every kind it knows and answers from the frozen
// records exactly (frozen_kinds.h).
#include <glintbake/runtime/glitter_ndf.h>
#include <glintbake/runtime/ltc.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/tensor_ndf.h>

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

}  // namespace
}  // namespace glintbake::runtime
