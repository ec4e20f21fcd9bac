// SPDX-License-Identifier: Apache-2.0
// A baked pyramid read back through the runtime, against the reference evaluator: exact at the
// centres, and the interpolation error between centres measured and printed.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/numbers.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/ndf_pyramid.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>
#include "../temp_dir.h"

namespace glintbake::runtime {
namespace {

TEST(NdfPyramidReference, CentresExactAndInterpolationErrorMeasured) {
  bake::MapParams mp;
  mp.size = 64;
  mp.seed = 9;
  const bake::NormalMap map = bake::generateMap(bake::MapKind::kBeckmann, mp);
  bake::ndf::PyramidOptions o;
  o.splat.ndf_res = 32;
  o.stride0 = 8;
  o.sigma0 = 4;
  o.levels = 3;
  const std::string path = glintbake::testing::processTempDir() + "rt_ref_pyramid.gbk";
  {
    format::Writer w;
    ASSERT_EQ(w.open(path, format::AssetKind::kNdfPyramid, 3), format::ContainerStatus::kOk);
    ASSERT_TRUE(bake::ndf::buildNdfPyramid(map, o, w, nullptr).ok());
    ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
  }
  NdfPyramid pyr;
  ASSERT_EQ(pyr.open(path.c_str()), RuntimeStatus::kOk);
  ASSERT_EQ(pyr.levelCount(), 3);
  const int res = pyr.resolution();
  const reference::FlakeSet flakes = reference::buildFlakes(map, 1);
  std::vector<float> img(size_t(res) * res);
  auto relL1 = [&](const std::vector<double>& ref) {
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < ref.size(); ++i) {
      num += std::fabs(img[i] - ref[i]);
      den += ref[i];
    }
    return num / den;
  };

  // At a level-0 centre with the level's sigma the runtime returns the stored splat. Its footprint
  // is the Gaussian divided by the sum of the level's footprints (a partition of unity, splat.h),
  // which moves a texel's weight by at most about 2 (a_x + a_y), a = exp(-2 pi^2 sigma^2 / stride^2)
  // per axis, and the image by no more in relative L1.
  const NdfLevelRecord* l0 = pyr.level(0);
  Footprint centre;
  centre.x = l0->origin_x + 2 * l0->stride_x;
  centre.y = l0->origin_y + 1 * l0->stride_y;
  centre.sigma = l0->sigma_texels;
  ASSERT_EQ(pyr.image(centre, img.data(), img.size()), RuntimeStatus::kOk);
  const float* stored = pyr.centreImage(0, 2, 1);
  ASSERT_NE(stored, nullptr);
  EXPECT_EQ(0, std::memcmp(stored, img.data(), img.size() * 4));
  reference::Footprint rf;
  rf.x = centre.x;
  rf.y = centre.y;
  rf.sigma = centre.sigma;
  const double a = std::exp(-2.0 * kPi * kPi * (centre.sigma * centre.sigma) / (l0->stride_x * l0->stride_x));
  const double centre_err = relL1(reference::binAveragedImage(flakes, rf, o.splat.sigma_r, res));
  std::printf("[ measured ] level-0 centre against the Gaussian footprint: relative L1 %.4f (bound %.4f)\n", centre_err,
              4.0 * a);
  EXPECT_LT(centre_err, 4.0 * a);

  // The plain trilinear blend (4 centres of each bracketing level), for comparison.
  auto trilinear = [&](double x, double y, double sigma) {
    std::vector<double> out(img.size(), 0.0);
    int l = 0;
    while (l + 1 < pyr.levelCount() && pyr.level(l + 1)->sigma_texels <= sigma) ++l;
    const int l2 = std::min(l + 1, pyr.levelCount() - 1);
    const double t = l2 == l ? 0.0
                             : std::log(sigma / pyr.level(l)->sigma_texels) /
                                   std::log(pyr.level(l2)->sigma_texels / pyr.level(l)->sigma_texels);
    for (int k = 0; k < 2; ++k) {
      const NdfLevelRecord* r = pyr.level(k == 0 ? l : l2);
      const double wl = k == 0 ? 1.0 - t : t;
      const double gx = (x - r->origin_x) / r->stride_x, gy = (y - r->origin_y) / r->stride_y;
      const int i0 = int(std::floor(gx)), j0 = int(std::floor(gy));
      for (int dj = 0; dj < 2; ++dj) {
        for (int di = 0; di < 2; ++di) {
          const double w = wl * (di ? gx - i0 : 1 - (gx - i0)) * (dj ? gy - j0 : 1 - (gy - j0));
          const int i = ((i0 + di) % int(r->grid_width) + int(r->grid_width)) % int(r->grid_width);
          const int j = ((j0 + dj) % int(r->grid_height) + int(r->grid_height)) % int(r->grid_height);
          const float* c = pyr.centreImage(k == 0 ? l : l2, i, j);
          for (size_t b = 0; b < out.size(); ++b) out[b] += w * c[b];
        }
      }
    }
    return out;
  };

  // Between centres and above level 0: the Gaussian footprint blend against the exact P-NDF of
  // that footprint, and against the trilinear blend of the same stored images (which is better only
  // at the centres of the upper levels, where it returns a stored image: the last case, 0.005 off
  // there, the partition's).
  const double cases[][3] = {{20.5, 37.25, 6.0}, {33.0, 9.0, 11.3}, {50.0, 60.0, 16.0}, {24.0, 8.0, 8.0}};
  for (const auto& c : cases) {
    Footprint f;
    f.x = c[0];
    f.y = c[1];
    f.sigma = c[2];
    ASSERT_EQ(pyr.image(f, img.data(), img.size()), RuntimeStatus::kOk);
    rf.x = c[0];
    rf.y = c[1];
    rf.sigma = c[2];
    const std::vector<double> ref = reference::binAveragedImage(flakes, rf, o.splat.sigma_r, res);
    const double err = relL1(ref);
    const std::vector<double> tri = trilinear(c[0], c[1], c[2]);
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < ref.size(); ++i) {
      num += std::fabs(tri[i] - ref[i]);
      den += ref[i];
    }
    std::printf("[ measured ] blend error at (%.2f, %.2f) sigma %.2f: relative L1 %.3f (trilinear %.3f)\n", c[0], c[1],
                c[2], err, num / den);
    EXPECT_LT(err, 0.06);
    if (&c != &cases[3]) {
      EXPECT_LT(err, num / den);
    }
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace glintbake::runtime
