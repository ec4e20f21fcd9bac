// SPDX-License-Identifier: Apache-2.0
// Runtime-lite LTC: polygon integration against quadrature, winding, clipping, lookups, loading
// from containers (including malformed ones) and the C API.
#include <glintbake/format/container.h>
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/ltc.h>
#include <glintbake/runtime/ltc_c.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>
#include "../temp_dir.h"

namespace glintbake::runtime {
namespace {

// Form factor from the origin (normal +z) of the rectangle [x0, x1] x [y0, y1] at height h, by a
// midpoint rule of cos_receiver cos_light / (pi r^2) = h^2 / (pi r^4) over its area.
double rectangleFormFactor(double x0, double x1, double y0, double y1, double h) {
  constexpr int kSteps = 800;
  double sum = 0.0;
  const double dx = (x1 - x0) / kSteps, dy = (y1 - y0) / kSteps;
  for (int i = 0; i < kSteps; ++i) {
    for (int j = 0; j < kSteps; ++j) {
      const double x = x0 + (i + 0.5) * dx, y = y0 + (j + 0.5) * dy;
      const double r2 = x * x + y * y + h * h;
      sum += h * h / (kPi * r2 * r2);
    }
  }
  return sum * dx * dy;
}

TEST(LtcPolygon, FormFactorMatchesQuadrature) {
  const float quad[4][3] = {{-0.5f, -1.0f, 1.0f}, {1.5f, -1.0f, 1.0f}, {1.5f, 0.5f, 1.0f}, {-0.5f, 0.5f, 1.0f}};
  const double expected = rectangleFormFactor(-0.5, 1.5, -1.0, 0.5, 1.0);
  EXPECT_NEAR(ltcFormFactor(quad, 4, false), expected, 1e-4);
  // Reversed winding: back face, 0 unless two-sided.
  const float reversed[4][3] = {{-0.5f, 0.5f, 1.0f}, {1.5f, 0.5f, 1.0f}, {1.5f, -1.0f, 1.0f}, {-0.5f, -1.0f, 1.0f}};
  EXPECT_EQ(ltcFormFactor(reversed, 4, false), 0.0f);
  EXPECT_NEAR(ltcFormFactor(reversed, 4, true), expected, 1e-4);
}

TEST(LtcPolygon, ClipsToHorizon) {
  // A vertical quad in the plane x = 1 straddling the horizon: only its upper half contributes.
  const float straddling[4][3] = {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}};
  const float upper[4][3] = {{1, -1, 0}, {1, 1, 0}, {1, 1, 1}, {1, -1, 1}};
  const float a = ltcFormFactor(straddling, 4, true);
  EXPECT_GT(a, 0.0f);
  EXPECT_NEAR(a, ltcFormFactor(upper, 4, true), 1e-6);
  const float below[3][3] = {{1, 0, -1}, {0, 1, -1}, {-1, 0, -1}};
  EXPECT_EQ(ltcFormFactor(below, 3, true), 0.0f);
  EXPECT_EQ(ltcFormFactor(upper, 2, true), 0.0f);  // too few vertices
}

TEST(LtcPolygon, HemisphereGivesOne) {
  const float big = 1e6f;
  const float quad[4][3] = {{-big, -big, 1e-4f}, {big, -big, 1e-4f}, {big, big, 1e-4f}, {-big, big, 1e-4f}};
  EXPECT_NEAR(ltcFormFactor(quad, 4, false), 1.0f, 1e-4f);
}

TEST(LtcPolygon, ShadingFrame) {
  const float n[3] = {0, 0, 1};
  const float v[3] = {0.6f, 0.0f, 0.8f};
  float x[3], y[3], z[3];
  ltcShadingFrame(n, v, x, y, z);
  EXPECT_NEAR(x[0], 1.0f, 1e-6f);
  EXPECT_NEAR(y[1], 1.0f, 1e-6f);
  EXPECT_NEAR(ltcCosTheta(n, v), 0.8f, 1e-6f);
  const float v_normal[3] = {0, 0, 1};
  ltcShadingFrame(n, v_normal, x, y, z);
  EXPECT_NEAR(x[0] * x[0] + x[1] * x[1] + x[2] * x[2], 1.0f, 1e-6f);
  EXPECT_NEAR(x[2], 0.0f, 1e-6f);
}

// A small synthetic table: ltc_1 = (1 + a, 0.1 t, 0, 1), ltc_2 = (a, t, 0, 1).
void makeTable(int n, std::vector<float>* l1, std::vector<float>* l2) {
  l1->assign(size_t(n) * n * 4, 0.0f);
  l2->assign(size_t(n) * n * 4, 0.0f);
  for (int t = 0; t < n; ++t) {
    for (int a = 0; a < n; ++a) {
      float* p = &(*l1)[size_t(a + n * t) * 4];
      p[0] = 1.0f + float(a), p[1] = 0.1f * float(t), p[3] = 1.0f;
      float* q = &(*l2)[size_t(a + n * t) * 4];
      q[0] = float(a), q[1] = float(t), q[3] = 1.0f;
    }
  }
}

TEST(LtcTableRuntime, BilinearLookupInPublishedParametrisation) {
  std::vector<float> l1, l2;
  makeTable(5, &l1, &l2);
  LtcTable table;
  ASSERT_EQ(table.fromArrays(5, l1.data(), l2.data()), RuntimeStatus::kOk);
  LtcCoefficients c;
  // roughness 0.375 -> a = 1.5; cos = 1 - (2.5/4)^2 -> t = 2.5.
  const float x = 2.5f / 4.0f;
  ASSERT_EQ(table.lookup(0.375f, 1.0f - x * x, &c), RuntimeStatus::kOk);
  EXPECT_NEAR(c.norm, 1.5f, 1e-5f);
  EXPECT_NEAR(c.fresnel, 2.5f, 1e-4f);
  EXPECT_NEAR(c.inv_m[0][0], 2.5f, 1e-5f);
  EXPECT_NEAR(c.inv_m[2][0], 0.25f, 1e-5f);
  EXPECT_EQ(c.inv_m[1][1], 1.0f);
  EXPECT_NEAR(ltcFresnelMagnitude(c, 0.5f), 2.0f, 1e-4f);
  EXPECT_EQ(table.lookup(NAN, 0.5f, &c), RuntimeStatus::kInvalidArgument);
  // Clamping outside the range.
  ASSERT_EQ(table.lookup(7.0f, -3.0f, &c), RuntimeStatus::kOk);
  EXPECT_NEAR(c.norm, 4.0f, 1e-6f);
  EXPECT_NEAR(c.fresnel, 4.0f, 1e-6f);
}

std::vector<uint8_t> imageSection(int n, const std::vector<float>& values, uint32_t channels = 4) {
  format::ImageSectionHeader header;
  header.width = header.height = uint32_t(n);
  header.channels = channels;
  std::vector<uint8_t> bytes(sizeof(header) + values.size() * sizeof(float));
  std::memcpy(bytes.data(), &header, sizeof(header));
  std::memcpy(bytes.data() + sizeof(header), values.data(), values.size() * sizeof(float));
  return bytes;
}

std::string writeContainer(const std::string& name, format::AssetKind kind, const std::vector<uint8_t>& s0,
                           const std::vector<uint8_t>& s1) {
  const std::string path = glintbake::testing::processTempDir() + name;
  format::Writer writer;
  EXPECT_EQ(writer.open(path, kind), format::ContainerStatus::kOk);
  EXPECT_EQ(writer.addSection(format::kSectionLtcTable, 0, s0.data(), s0.size()), format::ContainerStatus::kOk);
  EXPECT_EQ(writer.addSection(format::kSectionLtcTable, 1, s1.data(), s1.size()), format::ContainerStatus::kOk);
  EXPECT_EQ(writer.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(writer.finish(), format::ContainerStatus::kOk);
  return path;
}

TEST(LtcTableRuntime, LoadsContainersAndRefusesMalformedOnes) {
  std::vector<float> l1, l2;
  makeTable(6, &l1, &l2);
  const std::string good =
      writeContainer("ltc_good.gbk", format::AssetKind::kLtcTable, imageSection(6, l1), imageSection(6, l2));
  LtcTable table;
  ASSERT_EQ(table.open(good.c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(table.size(), 6);
  EXPECT_EQ(std::memcmp(table.ltc1(), l1.data(), l1.size() * sizeof(float)), 0);

  const std::string wrong_kind =
      writeContainer("ltc_kind.gbk", format::AssetKind::kTest, imageSection(6, l1), imageSection(6, l2));
  EXPECT_EQ(LtcTable().open(wrong_kind.c_str()), RuntimeStatus::kWrongKind);

  std::vector<float> l2_small;
  makeTable(5, &l1, &l2_small);
  const std::string mismatched =
      writeContainer("ltc_mismatch.gbk", format::AssetKind::kLtcTable, imageSection(6, l2), imageSection(5, l2_small));
  EXPECT_EQ(LtcTable().open(mismatched.c_str()), RuntimeStatus::kInvalidAsset);

  std::vector<float> bad = l2;
  bad[3] = NAN;
  const std::string nonfinite =
      writeContainer("ltc_nan.gbk", format::AssetKind::kLtcTable, imageSection(6, l2), imageSection(6, bad));
  EXPECT_EQ(LtcTable().open(nonfinite.c_str()), RuntimeStatus::kInvalidAsset);

  EXPECT_EQ(LtcTable().open((glintbake::testing::processTempDir() + "missing.gbk").c_str()), RuntimeStatus::kIoError);
  const uint8_t garbage[64] = {1, 2, 3};
  EXPECT_NE(LtcTable().openMemory(garbage, sizeof(garbage)), RuntimeStatus::kOk);
  for (const auto& path : {good, wrong_kind, mismatched, nonfinite}) std::remove(path.c_str());
}

TEST(LtcCApi, RoundTrip) {
  std::vector<float> l1, l2;
  makeTable(4, &l1, &l2);
  gb_ltc_table* table = nullptr;
  ASSERT_EQ(gb_ltc_table_from_arrays(4, l1.data(), l2.data(), &table), 0);
  int32_t size = 0;
  EXPECT_EQ(gb_ltc_table_size(table, &size), 0);
  EXPECT_EQ(size, 4);
  gb_ltc ltc;
  ASSERT_EQ(gb_ltc_lookup(table, 0.0f, 1.0f, &ltc), 0);
  EXPECT_EQ(ltc.inv_m[0], 1.0f);
  EXPECT_EQ(ltc.inv_m[4], 1.0f);
  EXPECT_EQ(ltc.inv_m[8], 1.0f);
  // Identity LTC: the integral is the form factor.
  const float quad[12] = {-0.5f, -1.0f, 1.0f, 1.5f, -1.0f, 1.0f, 1.5f, 0.5f, 1.0f, -0.5f, 0.5f, 1.0f};
  float value = 0.0f;
  ASSERT_EQ(gb_ltc_integrate_polygon(&ltc, quad, 4, 0, &value), 0);
  EXPECT_NEAR(value, rectangleFormFactor(-0.5, 1.5, -1.0, 0.5, 1.0), 1e-4);
  EXPECT_NE(gb_ltc_integrate_polygon(&ltc, quad, 2, 0, &value), 0);
  gb_ltc_table* missing = nullptr;
  EXPECT_NE(gb_ltc_table_open("/nonexistent/ltc.gbk", &missing), 0);
  EXPECT_EQ(missing, nullptr);
  gb_ltc_table_close(table);
  gb_ltc_table_close(nullptr);
}

}  // namespace
}  // namespace glintbake::runtime
