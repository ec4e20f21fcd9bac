// SPDX-License-Identifier: Apache-2.0
// Normal-map ingest: every file encoding, channel layouts, height fields, wrap modes, repairs and
// failures. Inputs are written with OIIO directly into a scratch directory.
#include <glintbake/bake/io/normal_map.h>

#include "test_support.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace glintbake::bake {
namespace {

using test::ScratchDir;
using test::writeFloats;
using test::writeRaw;

constexpr int kW = 24, kH = 20;

// A smooth field of unit normals with both signs in x and y.
void referenceNormal(int c, int r, float n[3]) {
  n[0] = float(0.5 * std::sin(0.7 * c + 0.3 * r));
  n[1] = float(0.4 * std::cos(0.5 * c - 0.9 * r));
  n[2] = std::sqrt(1.0f - n[0] * n[0] - n[1] * n[1]);
}

std::vector<float> referencePixels(int channels, bool encoded) {
  std::vector<float> px(size_t(kW) * kH * size_t(channels), 1.0f);
  for (int r = 0; r < kH; ++r) {
    for (int c = 0; c < kW; ++c) {
      float n[3];
      referenceNormal(c, r, n);
      float* p = &px[(size_t(r) * kW + size_t(c)) * size_t(channels)];
      for (int k = 0; k < std::min(channels, 3); ++k) p[k] = encoded ? 0.5f * n[k] + 0.5f : n[k];
    }
  }
  return px;
}

void expectMatchesReference(const NormalMap& map, double tolerance, bool flipped = false) {
  ASSERT_EQ(map.width, kW);
  ASSERT_EQ(map.height, kH);
  double worst = 0.0;
  for (int r = 0; r < kH; ++r) {
    for (int c = 0; c < kW; ++c) {
      float n[3];
      referenceNormal(c, r, n);
      if (flipped) n[1] = -n[1];
      const float* m = map.at(c, r);
      for (int k = 0; k < 3; ++k) worst = std::max(worst, double(std::abs(m[k] - n[k])));
      const double len = std::sqrt(double(m[0]) * m[0] + double(m[1]) * m[1] + double(m[2]) * m[2]);
      EXPECT_NEAR(len, 1.0, 1e-5);
    }
  }
  EXPECT_LT(worst, tolerance);
}

Result<NormalMap> load(const std::string& path, IngestReport* report, IngestOptions options = {}) {
  return loadNormalMap(path, options, report);
}

TEST(Ingest, Png8Bit) {
  ScratchDir dir;
  const std::string path = dir.file("n8.png");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::UINT8, referencePixels(3, true));
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  expectMatchesReference(map.value(), 2.5 / 255.0 * 2.0);
  EXPECT_EQ(report.pixel_type, "uint8");
  EXPECT_EQ(report.channels_in, 3);
  EXPECT_EQ(report.encoding_used, Encoding::kUnorm);
  EXPECT_EQ(report.texels, int64_t(kW) * kH);
  EXPECT_EQ(report.far_from_unit, 0);
  EXPECT_EQ(report.content_hash.rfind("xxh3-128:", 0), 0u);
  EXPECT_EQ(report.content_hash.size(), 9u + 32u);
}

TEST(Ingest, Png16BitWithAlphaIgnored) {
  ScratchDir dir;
  const std::string path = dir.file("n16.png");
  std::vector<float> px = referencePixels(4, true);
  for (size_t i = 3; i < px.size(); i += 4) px[i] = 0.25f;  // alpha must not matter
  writeFloats(path, kW, kH, 4, OIIO::TypeDesc::UINT16, px);
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  expectMatchesReference(map.value(), 4e-5);
  EXPECT_EQ(report.pixel_type, "uint16");
  EXPECT_EQ(report.channels_in, 4);
}

TEST(Ingest, ExrHalfScanlineSignedAutoDetected) {
  ScratchDir dir;
  const std::string path = dir.file("signed.exr");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::HALF, referencePixels(3, false));
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.encoding_used, Encoding::kSnorm);
  EXPECT_EQ(report.pixel_type, "half");
  expectMatchesReference(map.value(), 2e-3);
}

TEST(Ingest, ExrFloatTiledUnsignedAutoDetected) {
  ScratchDir dir;
  const std::string path = dir.file("tiled.exr");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::FLOAT, referencePixels(3, true), /*tiled=*/true);
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.encoding_used, Encoding::kUnorm);
  EXPECT_EQ(report.pixel_type, "float");
  expectMatchesReference(map.value(), 1e-5);
}

TEST(Ingest, EncodingOverrideForcesInterpretation) {
  ScratchDir dir;
  const std::string path = dir.file("encoded.exr");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::FLOAT, referencePixels(3, true));
  IngestOptions options;
  options.encoding = Encoding::kSnorm;  // wrong on purpose: values are used as they are
  IngestReport report;
  auto map = load(path, &report, options);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.encoding_used, Encoding::kSnorm);
  // (0.5 n + 0.5) taken as a normal: x and y are all positive now.
  float n[3];
  referenceNormal(3, 4, n);
  const float* m = map.value().at(3, 4);
  const float v[3] = {0.5f * n[0] + 0.5f, 0.5f * n[1] + 0.5f, 0.5f * n[2] + 0.5f};
  const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m[k], v[k] / len, 1e-5);
}

TEST(Ingest, Tiff16Bit) {
  ScratchDir dir;
  const std::string path = dir.file("n.tif");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::UINT16, referencePixels(3, true));
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.file_format, "tiff");
  expectMatchesReference(map.value(), 4e-5);
}

TEST(Ingest, JpegWhereAvailable) {
  const std::string formats = OIIO::get_string_attribute("extension_list");
  if (formats.find("jpg") == std::string::npos) GTEST_SKIP() << "OIIO built without JPEG";
  ScratchDir dir;
  const std::string path = dir.file("n.jpg");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::UINT8, referencePixels(3, true));
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.file_format, "jpeg");
  expectMatchesReference(map.value(), 0.1);  // lossy: a loose bound that still catches decoding errors
}

TEST(Ingest, FlipGreenNegatesY) {
  ScratchDir dir;
  const std::string path = dir.file("dx.png");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::UINT16, referencePixels(3, true));
  IngestOptions options;
  options.flip_green = true;
  auto map = load(path, nullptr, options);
  ASSERT_TRUE(map.ok()) << map.error().message;
  expectMatchesReference(map.value(), 4e-5, /*flipped=*/true);
}

TEST(Ingest, TwoChannelXYReconstructsZ) {
  ScratchDir dir;
  const std::string path = dir.file("xy.exr");
  std::vector<float> px(size_t(kW) * kH * 2);
  for (int r = 0; r < kH; ++r) {
    for (int c = 0; c < kW; ++c) {
      float n[3];
      referenceNormal(c, r, n);
      px[(size_t(r) * kW + size_t(c)) * 2 + 0] = n[0];
      px[(size_t(r) * kW + size_t(c)) * 2 + 1] = n[1];
    }
  }
  writeFloats(path, kW, kH, 2, OIIO::TypeDesc::FLOAT, px);
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.channels_in, 2);
  expectMatchesReference(map.value(), 1e-5);
}

TEST(Ingest, HeightFieldPlaneGivesKnownNormal) {
  ScratchDir dir;
  const std::string path = dir.file("plane.exr");
  // h = a c + b r: dh/dx = a, and with y up (decreasing rows) dh/dy_up = -b.
  const double a = 0.03, b = -0.05, k = 4.0;
  std::vector<float> h(size_t(kW) * kH);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c) h[size_t(r) * kW + size_t(c)] = float(a * c + b * r);
  writeFloats(path, kW, kH, 1, OIIO::TypeDesc::FLOAT, h);
  IngestOptions options;
  options.height = true;
  options.height_scale = k;
  options.wrap = Wrap::kClamp;
  auto map = load(path, nullptr, options);
  ASSERT_TRUE(map.ok()) << map.error().message;
  const double gx = -k * a, gy = k * b;
  const double inv = 1.0 / std::sqrt(gx * gx + gy * gy + 1.0);
  for (int r = 1; r < kH - 1; ++r) {
    for (int c = 1; c < kW - 1; ++c) {
      const float* n = map.value().at(c, r);
      EXPECT_NEAR(n[0], gx * inv, 1e-5);
      EXPECT_NEAR(n[1], gy * inv, 1e-5);
      EXPECT_NEAR(n[2], inv, 1e-5);
    }
  }
  // A tilted plane must tilt its normal away from the rising direction: h grows to the right, so
  // the normal leans left (n_x < 0).
  EXPECT_LT(map.value().at(5, 5)[0], 0.0f);

  // Clamp at the left edge: dh/dx = (h[1] - h[0]) / 2. Repeat: (h[1] - h[W-1]) / 2.
  auto edge_nx = [&](double dhdx, double dhdy_up) {
    const double ex = -k * dhdx, ey = -k * dhdy_up;
    return ex / std::sqrt(ex * ex + ey * ey + 1.0);
  };
  EXPECT_NEAR(map.value().at(0, 5)[0], edge_nx(0.5 * a, -b), 1e-5);
  options.wrap = Wrap::kRepeat;
  auto wrapped = load(path, nullptr, options);
  ASSERT_TRUE(wrapped.ok());
  EXPECT_NEAR(wrapped.value().at(0, 5)[0], edge_nx(0.5 * (a - a * (kW - 1)), -b), 1e-5);
  EXPECT_NEAR(wrapped.value().at(5, 5)[0], map.value().at(5, 5)[0], 1e-6);

  options.height_scale = 0.0;
  auto bad_scale = load(path, nullptr, options);
  ASSERT_FALSE(bad_scale.ok());
  EXPECT_EQ(bad_scale.error().code, ErrorCode::kBadArgument);
}

TEST(Ingest, SingleChannelNeedsHeightFlag) {
  ScratchDir dir;
  const std::string path = dir.file("gray.png");
  std::vector<float> h(size_t(kW) * kH, 0.5f);
  writeFloats(path, kW, kH, 1, OIIO::TypeDesc::UINT8, h);
  auto map = load(path, nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(map.error().message.find("channel count 1"), std::string::npos) << map.error().message;
  EXPECT_NE(map.error().message.find("gray.png"), std::string::npos);
}

TEST(Ingest, FiveChannelsRefused) {
  ScratchDir dir;
  const std::string path = dir.file("five.exr");
  writeFloats(path, 4, 4, 5, OIIO::TypeDesc::FLOAT, std::vector<float>(4 * 4 * 5, 0.5f));
  auto map = load(path, nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(map.error().message.find("channel count 5"), std::string::npos) << map.error().message;
}

TEST(Ingest, PartSelectsSubimage) {
  ScratchDir dir;
  const std::string path = dir.file("parts.exr");
  {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->supports("multiimage"));
    OIIO::ImageSpec specs[2] = {OIIO::ImageSpec(4, 4, 3, OIIO::TypeDesc::FLOAT),
                                OIIO::ImageSpec(4, 4, 3, OIIO::TypeDesc::FLOAT)};
    specs[0].attribute("name", "first");
    specs[1].attribute("name", "second");
    const std::vector<float> tilted = [] {
      std::vector<float> v(16 * 3);
      for (size_t i = 0; i < 16; ++i) {
        v[i * 3] = 0.6f;
        v[i * 3 + 1] = 0.0f;
        v[i * 3 + 2] = 0.8f;
      }
      return v;
    }();
    std::vector<float> flat(16 * 3, 0.0f);
    for (size_t i = 0; i < 16; ++i) flat[i * 3 + 2] = 1.0f;
    ASSERT_TRUE(out->open(path, 2, specs)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, flat.data()));
    ASSERT_TRUE(out->open(path, specs[1], OIIO::ImageOutput::AppendSubimage)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, tilted.data()));
    ASSERT_TRUE(out->close());
  }
  IngestOptions options;
  options.encoding = Encoding::kSnorm;
  auto first = load(path, nullptr, options);
  ASSERT_TRUE(first.ok()) << first.error().message;
  EXPECT_NEAR(first.value().at(1, 1)[2], 1.0f, 1e-6);
  options.part = 1;
  auto second = load(path, nullptr, options);
  ASSERT_TRUE(second.ok()) << second.error().message;
  EXPECT_NEAR(second.value().at(1, 1)[0], 0.6f, 1e-6);
  options.part = 2;
  auto missing = load(path, nullptr, options);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kBadArgument);
  EXPECT_NE(missing.error().message.find("part 2"), std::string::npos) << missing.error().message;
}

TEST(Ingest, WrapFetch) {
  NormalMap map;
  map.width = 3;
  map.height = 2;
  map.normals.resize(3 * 2 * 3);
  for (int i = 0; i < 6; ++i) map.normals[size_t(i) * 3] = float(i);  // x holds the texel index
  map.wrap = Wrap::kRepeat;
  EXPECT_EQ(map.fetch(-1, 0)[0], 2.0f);
  EXPECT_EQ(map.fetch(3, 1)[0], 3.0f);
  EXPECT_EQ(map.fetch(-4, -1)[0], 5.0f);
  EXPECT_EQ(map.fetch(7, 4)[0], 1.0f);
  map.wrap = Wrap::kClamp;
  EXPECT_EQ(map.fetch(-1, 0)[0], 0.0f);
  EXPECT_EQ(map.fetch(3, 1)[0], 5.0f);
  EXPECT_EQ(map.fetch(-4, -1)[0], 0.0f);
  EXPECT_EQ(map.fetch(7, 4)[0], 5.0f);
  EXPECT_EQ(map.fetch(1, 1)[0], 4.0f);
}

TEST(Ingest, NonFiniteIsAnErrorUnlessFixed) {
  ScratchDir dir;
  const std::string path = dir.file("nan.exr");
  std::vector<float> px = referencePixels(3, false);
  px[(size_t(3) * kW + 5) * 3 + 1] = std::numeric_limits<float>::quiet_NaN();
  px[(size_t(7) * kW + 2) * 3 + 2] = std::numeric_limits<float>::infinity();
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::FLOAT, px);

  auto failed = load(path, nullptr);
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ErrorCode::kInvalidInput);
  const std::string& msg = failed.error().message;
  EXPECT_NE(msg.find("2 texel(s)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("column 5, row 3"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos);

  IngestOptions options;
  options.fix_nonfinite = true;
  IngestReport report;
  auto fixed = load(path, &report, options);
  ASSERT_TRUE(fixed.ok()) << fixed.error().message;
  EXPECT_EQ(report.nonfinite, 2);
  const float* n = fixed.value().at(5, 3);
  EXPECT_EQ(n[0], 0.0f);
  EXPECT_EQ(n[1], 0.0f);
  EXPECT_EQ(n[2], 1.0f);
  EXPECT_EQ(fixed.value().at(2, 7)[2], 1.0f);
}

TEST(Ingest, NonFiniteHeights) {
  ScratchDir dir;
  const std::string path = dir.file("h.exr");
  std::vector<float> h(size_t(kW) * kH);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c) h[size_t(r) * kW + size_t(c)] = float(0.1 * c);
  h[size_t(4) * kW + 6] = std::numeric_limits<float>::quiet_NaN();
  writeFloats(path, kW, kH, 1, OIIO::TypeDesc::FLOAT, h);
  IngestOptions options;
  options.height = true;
  auto failed = load(path, nullptr, options);
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(failed.error().message.find("column 6, row 4"), std::string::npos) << failed.error().message;

  options.fix_nonfinite = true;
  IngestReport report;
  auto fixed = load(path, &report, options);
  ASSERT_TRUE(fixed.ok()) << fixed.error().message;
  EXPECT_EQ(report.nonfinite, 1);
  EXPECT_EQ(fixed.value().at(6, 4)[2], 1.0f);
  for (float v : fixed.value().normals) EXPECT_TRUE(std::isfinite(v));
}

TEST(Ingest, NonPositiveZRepairedAndCounted) {
  const float px[4 * 3] = {0.6f,  0.8f, -0.5f,  // below: kept azimuth, on the horizon
                           0.0f,  0.0f, -1.0f,  // straight down: no azimuth, becomes up
                           -3.0f, 4.0f, 0.0f,   // on the horizon, long: normalised
                           0.0f,  0.0f, 1.0f};
  IngestReport report;
  auto map = normalMapFromPixels(2, 2, 3, px, IngestOptions{}, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.nz_nonpositive, 3);
  const NormalMap& m = map.value();
  EXPECT_NEAR(m.at(0, 0)[0], 0.6f, 1e-6);
  EXPECT_NEAR(m.at(0, 0)[1], 0.8f, 1e-6);
  EXPECT_EQ(m.at(0, 0)[2], 0.0f);
  EXPECT_EQ(m.at(1, 0)[2], 1.0f);
  EXPECT_NEAR(m.at(0, 1)[0], -0.6f, 1e-6);
  EXPECT_NEAR(m.at(0, 1)[1], 0.8f, 1e-6);
  EXPECT_EQ(m.at(1, 1)[2], 1.0f);
  for (size_t i = 2; i < m.normals.size(); i += 3) EXPECT_GE(m.normals[i], 0.0f);
}

TEST(Ingest, FarFromUnitCountedWithMeanLength) {
  const float px[2 * 3] = {0.0f, 0.0f, 0.5f, 0.0f, 0.6f, 0.8f};
  IngestReport report;
  auto map = normalMapFromPixels(2, 1, 3, px, IngestOptions{}, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.far_from_unit, 1);
  EXPECT_NEAR(report.mean_length, 0.75, 1e-6);
  EXPECT_EQ(map.value().at(0, 0)[2], 1.0f);

  IngestOptions loose;
  loose.unit_tolerance = 0.6;
  auto again = normalMapFromPixels(2, 1, 3, px, loose, &report);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(report.far_from_unit, 0);
}

TEST(Ingest, EightBitMapsFarFromUnitAreReported) {
  ScratchDir dir;
  const std::string path = dir.file("short.png");
  std::vector<float> px = referencePixels(3, false);
  for (float& v : px) v = 0.5f * (0.6f * v) + 0.5f;  // every normal shortened to length 0.6
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::UINT8, px);
  IngestReport report;
  auto map = load(path, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(report.far_from_unit, report.texels);
  EXPECT_NEAR(report.mean_length, 0.6, 0.01);
  expectMatchesReference(map.value(), 0.02);
}

TEST(Ingest, TooLargeIsRefused) {
  ScratchDir dir;
  const std::string path = dir.file("big.png");
  writeFloats(path, kW, kH, 3, OIIO::TypeDesc::UINT8, referencePixels(3, true));
  IngestOptions options;
  options.max_size = 16;
  auto map = load(path, nullptr, options);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput);
  const std::string& msg = map.error().message;
  EXPECT_NE(msg.find("24x20"), std::string::npos) << msg;
  EXPECT_NE(msg.find("16"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--max-size"), std::string::npos) << msg;
}

void expectOneLineNaming(const Error& error, const std::string& name) {
  EXPECT_EQ(error.message.find('\n'), std::string::npos) << error.message;
  EXPECT_NE(error.message.find(name), std::string::npos) << error.message;
}

TEST(Ingest, TruncatedFileIsInvalid) {
  ScratchDir dir;
  for (const char* name : {"cut.png", "cut.exr"}) {
    const std::string path = dir.file(name);
    writeFloats(path, 64, 64, 3,
                std::string(name).find(".png") != std::string::npos ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::FLOAT,
                std::vector<float>(64 * 64 * 3, 0.5f));
    const std::string bytes = test::readBytes(path);
    test::writeBytes(path, bytes.substr(0, bytes.size() / 2));
    auto map = load(path, nullptr);
    ASSERT_FALSE(map.ok()) << name;
    EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput) << map.error().message;
    expectOneLineNaming(map.error(), name);
  }
}

// Constant maps compress far better than real ones: every codec whose ratio bounds the file size
// must still accept them (the bound is what the codec can reach, never a typical ratio). One test
// per codec (suite IngestCompressible, apart from Ingest's, which the sanitizer run gives full
// malloc stacks): each writes and reads a 2048^2 map, and they run in parallel.
struct CompressibleCase {
  const char* name;
  OIIO::TypeDesc stored;
  const char* compression;
  bool tiled;
};

class IngestCompressible : public ::testing::TestWithParam<CompressibleCase> {};

TEST_P(IngestCompressible, LargeFlatMapsStillLoad) {
  const CompressibleCase& c = GetParam();
  ScratchDir dir;
  const int side = 2048;
  const std::vector<float> flat(size_t(side) * side * 3, 0.5f);
  const std::string path = dir.file(c.name);
  // Tiles of 64 (OpenImageIO's default): OpenEXR writes 2048^2 pixels as 16 x 16 PIZ tiles in
  // half a minute, and larger tiles compress better, so the bound is tested harder.
  writeFloats(path, side, side, 3, c.stored, flat, c.tiled, c.compression, 64);
  auto map = load(path, nullptr);
  ASSERT_TRUE(map.ok()) << c.name << ": " << map.error().message;
  EXPECT_EQ(map.value().width, side) << c.name;
}

INSTANTIATE_TEST_SUITE_P(EveryCodec, IngestCompressible,
                         ::testing::Values(CompressibleCase{"flat8.png", OIIO::TypeDesc::UINT8, "zip:9", false},
                                           CompressibleCase{"flat16.png", OIIO::TypeDesc::UINT16, "zip:9", false},
                                           CompressibleCase{"zip.exr", OIIO::TypeDesc::HALF, "zip", false},
                                           CompressibleCase{"zips.exr", OIIO::TypeDesc::FLOAT, "zips", false},
                                           CompressibleCase{"rle.exr", OIIO::TypeDesc::HALF, "rle", true},
                                           CompressibleCase{"pxr24.exr", OIIO::TypeDesc::FLOAT, "pxr24", false},
                                           CompressibleCase{"b44a.exr", OIIO::TypeDesc::HALF, "b44a", false},
                                           CompressibleCase{"piz.exr", OIIO::TypeDesc::HALF, "piz", false},
                                           CompressibleCase{"piz-tiled.exr", OIIO::TypeDesc::HALF, "piz", true},
                                           CompressibleCase{"dwaa.exr", OIIO::TypeDesc::HALF, "dwaa", false},
                                           CompressibleCase{"lzw.tif", OIIO::TypeDesc::UINT8, "lzw", false},
                                           CompressibleCase{"zip.tif", OIIO::TypeDesc::UINT16, "zip", false},
                                           CompressibleCase{"packbits.tif", OIIO::TypeDesc::UINT8, "packbits", false}),
                         [](const ::testing::TestParamInfo<CompressibleCase>& param) {
                           std::string name = param.param.name;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

// A file too small for the image its header declares is refused before the map is allocated.
TEST(Ingest, FileTooSmallForItsHeaderIsInvalid) {
  ScratchDir dir;
  const std::string path = dir.file("claims.png");
  writeFloats(path, 2048, 2048, 3, OIIO::TypeDesc::UINT8, std::vector<float>(size_t(2048) * 2048 * 3, 0.5f));
  std::string bytes = test::readBytes(path);
  // The same IHDR declaring 8192 x 8192 (width and height at bytes 16..23, then the CRC at 29).
  const unsigned char big[8] = {0, 0, 0x20, 0, 0, 0, 0x20, 0};
  bytes.replace(16, 8, reinterpret_cast<const char*>(big), 8);
  uint32_t crc = 0xFFFFFFFFu;  // CRC-32 of the chunk type and data (bytes 12..28)
  for (size_t i = 12; i < 29; ++i) {
    crc ^= uint8_t(bytes[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  crc = ~crc;
  for (int k = 0; k < 4; ++k) bytes[29 + size_t(k)] = char(crc >> (24 - 8 * k));
  test::writeBytes(path, bytes);
  auto map = load(path, nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput) << map.error().message;
  expectOneLineNaming(map.error(), "claims.png");
  EXPECT_NE(map.error().message.find("cannot hold the declared 8192x8192 image"), std::string::npos)
      << map.error().message;
}

// OpenEXR allocates header attributes at their declared size: one declaring more bytes than the
// file holds is refused before OIIO opens the file, in one line even when its name holds newlines
// (found by fuzz_ingest).
TEST(Ingest, ExrAttributeLargerThanTheFileIsInvalid) {
  ScratchDir dir;
  const std::string path = dir.file("attr.exr");
  std::string bytes("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  bytes += std::string("Soft\nware\0string\0", 17);
  bytes += std::string("\x00\x00\x00\x6e", 4);  // 1845493760 bytes
  bytes += std::string(512, 'x');
  test::writeBytes(path, bytes);
  auto map = load(path, nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput);
  expectOneLineNaming(map.error(), "attr.exr");
  EXPECT_NE(map.error().message.find("attribute 'Soft?ware' declares 1845493760 bytes"), std::string::npos)
      << map.error().message;
}

// libpng allocates a chunk at its declared length before reading it: a PNG whose chunk claims more
// bytes than the file holds is refused before OIIO opens it (found by fuzz_ingest: a 559-byte file
// whose tEXt chunk declared 1.9 GB).
TEST(Ingest, PngChunkLargerThanTheFileIsInvalid) {
  ScratchDir dir;
  const std::string path = dir.file("chunk.png");
  writeFloats(path, 4, 4, 3, OIIO::TypeDesc::UINT8, std::vector<float>(4 * 4 * 3, 0.5f));
  std::string bytes = test::readBytes(path);
  ASSERT_EQ(bytes.substr(12, 4), "IHDR");
  // After IHDR (8 signature + 12 framing + 13 data bytes): a tEXt chunk declaring 0x6f660000.
  std::string chunk("\x6f\x66\x00\x00tE\nt", 8);
  chunk += std::string(64, 'x');
  bytes.insert(33, chunk);
  test::writeBytes(path, bytes);
  auto map = load(path, nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput);
  expectOneLineNaming(map.error(), "chunk.png");
  EXPECT_NE(map.error().message.find("PNG chunk 'tE?t' declares 1868955648 bytes"), std::string::npos)
      << map.error().message;

  // A PNG cut inside a chunk is refused the same way, naming the chunk it ends in.
  writeFloats(path, 4, 4, 3, OIIO::TypeDesc::UINT8, std::vector<float>(4 * 4 * 3, 0.5f));
  const std::string cut = test::readBytes(path);
  const size_t idat = cut.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  test::writeBytes(path, cut.substr(0, idat + 6));
  map = load(path, nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(map.error().message.find("PNG chunk 'IDAT' declares"), std::string::npos) << map.error().message;
}

TEST(Ingest, GarbageFileIsInvalid) {
  ScratchDir dir;
  const std::string path = dir.file("garbage.png");
  std::string bytes;
  uint32_t state = 12345;
  for (int i = 0; i < 4096; ++i) {
    state = state * 1664525u + 1013904223u;
    bytes.push_back(char(state >> 24));
  }
  test::writeBytes(path, bytes);
  auto map = load(path, nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidInput);
  expectOneLineNaming(map.error(), "garbage.png");
}

TEST(Ingest, MissingFileIsIoError) {
  ScratchDir dir;
  auto map = load(dir.file("absent.exr"), nullptr);
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kIo);
  expectOneLineNaming(map.error(), "absent.exr");
  std::filesystem::create_directories(dir.file("folder.png"));
  auto folder = load(dir.file("folder.png"), nullptr);
  ASSERT_FALSE(folder.ok());
  EXPECT_EQ(folder.error().code, ErrorCode::kIo);
  expectOneLineNaming(folder.error(), "folder.png");
}

TEST(Ingest, ContentHashFollowsBytes) {
  ScratchDir dir;
  const std::string a = dir.file("a.png"), b = dir.file("b.png");
  std::vector<float> px = referencePixels(3, true);
  writeFloats(a, kW, kH, 3, OIIO::TypeDesc::UINT8, px);
  px[0] = 0.0f;
  writeFloats(b, kW, kH, 3, OIIO::TypeDesc::UINT8, px);
  IngestReport ra, rb, ra2;
  ASSERT_TRUE(load(a, &ra).ok());
  ASSERT_TRUE(load(b, &rb).ok());
  ASSERT_TRUE(load(a, &ra2).ok());
  EXPECT_EQ(ra.content_hash, ra2.content_hash);
  EXPECT_NE(ra.content_hash, rb.content_hash);
}

TEST(Ingest, PixelsEntryPointValidates) {
  const float px[3] = {0.0f, 0.0f, 1.0f};
  EXPECT_EQ(normalMapFromPixels(0, 1, 3, px, IngestOptions{}, nullptr).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(normalMapFromPixels(1, 1, 1, px, IngestOptions{}, nullptr).error().code, ErrorCode::kInvalidInput);
  IngestOptions small;
  small.max_size = 1;
  const float px4[4 * 3] = {};
  EXPECT_EQ(normalMapFromPixels(2, 2, 3, px4, small, nullptr).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace glintbake::bake
