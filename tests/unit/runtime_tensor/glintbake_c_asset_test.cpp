// SPDX-License-Identifier: Apache-2.0
// The C API's generic NDF asset handle: the same answers as the C++ classes for both asset kinds,
// kinds reported, and errors for missing files, other kinds and bad arguments.
#include <glintbake/runtime/glintbake_ndf_c.h>

#include "tensor_assets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace glintbake::runtime::testing {
namespace {

TEST(GlintbakeCAsset, TensorAndPyramidThroughOneHandle) {
  const TensorNdf& t = assets().nonneg;
  const std::string pyramid_path = writeReconstructedPyramid(t, "capi");
  NdfPyramid pyramid;
  ASSERT_EQ(pyramid.open(pyramid_path.c_str()), RuntimeStatus::kOk);

  gb_ndf_asset* ta = nullptr;
  gb_ndf_asset* pa = nullptr;
  ASSERT_EQ(gb_ndf_asset_open_memory(assets().nonneg_bytes.data(), assets().nonneg_bytes.size(), &ta), GB_OK);
  ASSERT_EQ(gb_ndf_asset_open(pyramid_path.c_str(), &pa), GB_OK);
  int32_t kind = 0, res = 0;
  ASSERT_EQ(gb_ndf_asset_info(ta, &kind, &res), GB_OK);
  EXPECT_EQ(kind, GB_KIND_TENSOR_NDF);
  EXPECT_EQ(res, 32);
  ASSERT_EQ(gb_ndf_asset_info(pa, &kind, nullptr), GB_OK);
  EXPECT_EQ(kind, GB_KIND_NDF_PYRAMID);
  // Map and footprint ranges, as the C++ interface reports them.
  int32_t w = 0, h = 0, wrap = -1;
  ASSERT_EQ(gb_ndf_asset_map(ta, &w, &h, &wrap), GB_OK);
  EXPECT_EQ(w, t.mapSize().width);
  EXPECT_EQ(h, t.mapSize().height);
  EXPECT_EQ(wrap, int32_t(t.wrap()));
  double exact = -1, band = -1, lo = -1, hi = -1;
  ASSERT_EQ(gb_ndf_asset_footprint_range(ta, &exact, &band, &lo, &hi), GB_OK);
  EXPECT_EQ(exact, t.footprintRange().exact_max_sigma);
  EXPECT_EQ(band, t.footprintRange().handover_max_sigma);
  EXPECT_EQ(lo, t.level(0)->sigma_texels);
  EXPECT_EQ(hi, t.level(t.levelCount() - 1)->sigma_texels);
  EXPECT_EQ(gb_ndf_asset_footprint_range(nullptr, nullptr, nullptr, nullptr, nullptr), GB_INVALID_ARGUMENT);
  EXPECT_EQ(gb_ndf_asset_map(nullptr, nullptr, nullptr, nullptr), GB_INVALID_ARGUMENT);

  const NdfSource* sources[2] = {&t, &pyramid};
  gb_ndf_asset* handles[2] = {ta, pa};
  for (int k = 0; k < 2; ++k) {
    Footprint fp;
    fp.x = 21.5;
    fp.y = 7.25;
    fp.sigma = 9.0;
    double a = -1.0, b = -2.0;
    ASSERT_EQ(gb_ndf_asset_eval(handles[k], fp.x, fp.y, fp.sigma, 0.03, -0.05, &a), GB_OK);
    ASSERT_EQ(sources[k]->eval(fp, SPoint{0.03, -0.05}, &b), RuntimeStatus::kOk);
    EXPECT_EQ(a, b);
    ASSERT_EQ(gb_ndf_asset_average(handles[k], fp.x, fp.y, fp.sigma, -0.2, -0.1, 0.3, 0.25, &a), GB_OK);
    SRect r;
    r.x0 = -0.2;
    r.y0 = -0.1;
    r.x1 = 0.3;
    r.y1 = 0.25;
    ASSERT_EQ(sources[k]->average(fp, r, &b), RuntimeStatus::kOk);
    EXPECT_EQ(a, b);
    ASSERT_EQ(gb_ndf_asset_mass(handles[k], fp.x, fp.y, fp.sigma, &a), GB_OK);
    // The weighted mean of the blended centres' masses (rank-16 models of a 64^2 map: 1 to 3%).
    EXPECT_NEAR(a, 1.0, 3e-2);
    double sx = 0.0, sy = 0.0, p = 0.0, q = -1.0;
    ASSERT_EQ(gb_ndf_asset_sample(handles[k], fp.x, fp.y, fp.sigma, 0.4, 0.6, &sx, &sy, &p), GB_OK);
    ASSERT_EQ(gb_ndf_asset_pdf(handles[k], fp.x, fp.y, fp.sigma, sx, sy, &q), GB_OK);
    EXPECT_EQ(p, q);
    std::vector<float> img(size_t(res) * res);
    ASSERT_EQ(gb_ndf_asset_image(handles[k], fp.x, fp.y, fp.sigma, img.data(), img.size()), GB_OK);
    EXPECT_EQ(gb_ndf_asset_image(handles[k], fp.x, fp.y, fp.sigma, img.data(), img.size() - 1), GB_INVALID_ARGUMENT);
    EXPECT_EQ(gb_ndf_asset_eval(handles[k], fp.x, fp.y, NAN, 0.0, 0.0, &a), GB_INVALID_ARGUMENT);
  }
  gb_ndf_asset_close(ta);
  gb_ndf_asset_close(pa);
  gb_ndf_asset_close(nullptr);
  std::remove(pyramid_path.c_str());
}

TEST(GlintbakeCAsset, Errors) {
  gb_ndf_asset* a = reinterpret_cast<gb_ndf_asset*>(&a);
  EXPECT_EQ(gb_ndf_asset_open(tempPath("missing.gbk").c_str(), &a), GB_IO_ERROR);
  EXPECT_EQ(a, nullptr);
  EXPECT_EQ(gb_ndf_asset_open(nullptr, &a), GB_INVALID_ARGUMENT);
  EXPECT_EQ(gb_ndf_asset_open_memory(nullptr, 0, &a), GB_INVALID_ARGUMENT);
  const char junk[] = "not a container, not at all, not even close to one of them";
  EXPECT_EQ(gb_ndf_asset_open_memory(junk, sizeof(junk), &a), GB_INVALID_ASSET);
  // A container of another asset kind.
  const std::string path = tempPath("other-kind.gbk");
  {
    format::Writer w;
    ASSERT_EQ(w.open(path, format::AssetKind::kLtcTable, 1), format::ContainerStatus::kOk);
    ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
  }
  EXPECT_EQ(gb_ndf_asset_open(path.c_str(), &a), GB_WRONG_KIND);
  std::remove(path.c_str());
  double v = 0.0;
  EXPECT_EQ(gb_ndf_asset_eval(nullptr, 0, 0, 1, 0, 0, &v), GB_INVALID_ARGUMENT);
  EXPECT_EQ(gb_ndf_asset_info(nullptr, nullptr, nullptr), GB_INVALID_ARGUMENT);
  EXPECT_STREQ(gb_status_string(GB_WRONG_KIND), statusString(RuntimeStatus::kWrongKind));
}

}  // namespace
}  // namespace glintbake::runtime::testing
