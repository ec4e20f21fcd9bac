// SPDX-License-Identifier: Apache-2.0
// Flake construction: positions, normals and Jacobians exactly per the flake model (SPEC.md).
#include <glintbake/reference/flakes.h>

#include "test_maps.h"

#include <gtest/gtest.h>

#include <cmath>

namespace glintbake::reference {
namespace {

TEST(ReferenceFlakes, Rate1UsesTexelNormalsAndNeighbourDifferences) {
  const bake::NormalMap map = testing::wavyMap(12, 9);
  const FlakeSet set = buildFlakes(map, 1);
  ASSERT_EQ(set.flakes.size(), size_t(12 * 9));
  EXPECT_DOUBLE_EQ(set.area, 1.0);
  EXPECT_NEAR(set.sigma_h, 1.5 / std::sqrt(12.0), 1e-15);
  for (int r = 0; r < map.height; ++r) {
    for (int c = 0; c < map.width; ++c) {
      const Flake& f = set.at(c, r);
      EXPECT_DOUBLE_EQ(f.u[0], c + 0.5);
      EXPECT_DOUBLE_EQ(f.u[1], r + 0.5);
      EXPECT_DOUBLE_EQ(f.n[0], map.at(c, r)[0]);
      EXPECT_DOUBLE_EQ(f.n[1], map.at(c, r)[1]);
      // Repeat wrap: neighbours across the edges come from the opposite side.
      const float* right = map.at((c + 1) % map.width, r);
      const float* left = map.at((c + map.width - 1) % map.width, r);
      const float* down = map.at(c, (r + 1) % map.height);
      const float* up = map.at(c, (r + map.height - 1) % map.height);
      EXPECT_NEAR(f.jacobian[0], (double(right[0]) - left[0]) / 2, 1e-15);
      EXPECT_NEAR(f.jacobian[1], (double(down[0]) - up[0]) / 2, 1e-15);
      EXPECT_NEAR(f.jacobian[2], (double(right[1]) - left[1]) / 2, 1e-15);
      EXPECT_NEAR(f.jacobian[3], (double(down[1]) - up[1]) / 2, 1e-15);
    }
  }
}

TEST(ReferenceFlakes, ClampRepeatsEdgeTexels) {
  const bake::NormalMap map = testing::wavyMap(6, 5, 0.3, bake::Wrap::kClamp);
  const FlakeSet set = buildFlakes(map, 1);
  const Flake& corner = set.at(0, 0);
  EXPECT_NEAR(corner.jacobian[0], (double(map.at(1, 0)[0]) - map.at(0, 0)[0]) / 2, 1e-15);
  EXPECT_NEAR(corner.jacobian[3], (double(map.at(0, 1)[1]) - map.at(0, 0)[1]) / 2, 1e-15);
  const Flake& last = set.at(5, 4);
  EXPECT_NEAR(last.jacobian[2], (double(map.at(5, 4)[1]) - map.at(4, 4)[1]) / 2, 1e-15);
}

TEST(ReferenceFlakes, SubSamplesInterpolateBilinearly) {
  const bake::NormalMap map = testing::wavyMap(7, 6);
  const FlakeSet set = buildFlakes(map, 2);
  ASSERT_EQ(set.fineWidth(), 14);
  EXPECT_DOUBLE_EQ(set.step, 0.5);
  EXPECT_DOUBLE_EQ(set.area, 0.25);
  EXPECT_NEAR(set.sigma_h, 0.5 * 1.5 / std::sqrt(12.0), 1e-15);
  // Fine point (5, 8) sits at u = (2.75, 4.25): between texel centres 2.5 / 3.5 (x, weight 0.75 on
  // column 2) and 3.5 / 4.5 (y, weights 0.25 on row 3, 0.75 on row 4).
  const Flake& f = set.at(5, 8);
  EXPECT_DOUBLE_EQ(f.u[0], 2.75);
  EXPECT_DOUBLE_EQ(f.u[1], 4.25);
  for (int k = 0; k < 2; ++k) {
    const double expected = 0.75 * 0.25 * map.at(2, 3)[k] + 0.25 * 0.25 * map.at(3, 3)[k] +
                            0.75 * 0.75 * map.at(2, 4)[k] + 0.25 * 0.75 * map.at(3, 4)[k];
    EXPECT_NEAR(f.n[k], expected, 1e-15);
  }
  // The wrapped sub-sample left of column 0 blends the last column.
  const Flake& edge = set.at(0, 0);  // u = (0.25, 0.25)
  const double expected = 0.25 * 0.25 * map.at(6, 5)[0] + 0.75 * 0.25 * map.at(0, 5)[0] +
                          0.25 * 0.75 * map.at(6, 0)[0] + 0.75 * 0.75 * map.at(0, 0)[0];
  EXPECT_NEAR(edge.n[0], expected, 1e-15);
}

TEST(ReferenceFlakes, JacobianOfALinearFieldIsExact) {
  // n_x = 0.01 * u_x, n_y = -0.02 * u_y at texel centres (a clamp map, inside only).
  bake::NormalMap map = testing::constantMap(10, 10, 0.0, 0.0, bake::Wrap::kClamp);
  for (int r = 0; r < 10; ++r) {
    for (int c = 0; c < 10; ++c) {
      map.at(c, r)[0] = float(0.01 * (c + 0.5));
      map.at(c, r)[1] = float(-0.02 * (r + 0.5));
    }
  }
  const FlakeSet set = buildFlakes(map, 4);
  const Flake& f = set.at(17, 22);  // u = (4.375, 5.625), two texels from every edge
  EXPECT_NEAR(f.n[0], 0.01 * 4.375, 1e-8);
  EXPECT_NEAR(f.n[1], -0.02 * 5.625, 1e-8);
  EXPECT_NEAR(f.jacobian[0], 0.01, 1e-7);
  EXPECT_NEAR(f.jacobian[1], 0.0, 1e-9);
  EXPECT_NEAR(f.jacobian[2], 0.0, 1e-9);
  EXPECT_NEAR(f.jacobian[3], -0.02, 1e-7);
}

}  // namespace
}  // namespace glintbake::reference
