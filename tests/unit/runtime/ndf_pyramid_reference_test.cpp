// A baked pyramid read back through the runtime, against the reference evaluator: exact at the
// centres, and the interpolation error between centres measured and printed.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
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
    ASSERT_EQ(w.open(path, format::AssetKind::kNdfPyramid, 3), format::Status::kOk);
    ASSERT_TRUE(bake::ndf::buildNdfPyramid(map, o, w, nullptr).ok());
    ASSERT_EQ(w.addMetadata("{}"), format::Status::kOk);
    ASSERT_EQ(w.finish(), format::Status::kOk);
  }
  NdfPyramid pyr;
  ASSERT_EQ(pyr.open(path.c_str()), Status::kOk);
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

  // At a centre with the level's sigma the runtime returns the stored splat, which matches the
  // reference to the splat's accuracy.
  const NdfLevelRecord* l1 = pyr.level(1);
  Footprint centre;
  centre.x = l1->origin_x + 2 * l1->stride_x;
  centre.y = l1->origin_y + 1 * l1->stride_y;
  centre.sigma = l1->sigma_texels;
  ASSERT_EQ(pyr.image(centre, img.data(), img.size()), Status::kOk);
  const float* stored = pyr.centreImage(1, 2, 1);
  ASSERT_NE(stored, nullptr);
  EXPECT_EQ(0, std::memcmp(stored, img.data(), img.size() * 4));
  reference::Footprint rf;
  rf.x = centre.x;
  rf.y = centre.y;
  rf.sigma = centre.sigma;
  EXPECT_LT(relL1(reference::binAveragedImage(flakes, rf, o.splat.sigma_r, res)), 1e-3);

  // Between centres and levels: the trilinear blend against the exact P-NDF of that footprint.
  const double cases[][3] = {{12.0, 12.0, 4.0}, {20.5, 37.25, 6.0}, {33.0, 9.0, 11.3}, {50.0, 60.0, 16.0}};
  for (const auto& c : cases) {
    Footprint f;
    f.x = c[0];
    f.y = c[1];
    f.sigma = c[2];
    ASSERT_EQ(pyr.image(f, img.data(), img.size()), Status::kOk);
    rf.x = c[0];
    rf.y = c[1];
    rf.sigma = c[2];
    const double err = relL1(reference::binAveragedImage(flakes, rf, o.splat.sigma_r, res));
    std::printf("[ measured ] interpolation error at (%.2f, %.2f) sigma %.2f: relative L1 %.3f\n", c[0], c[1], c[2],
                err);
    EXPECT_LT(err, 2.0);  // a measurement: the blend is a mixture of nearby footprints, not exact
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace glintbake::runtime
