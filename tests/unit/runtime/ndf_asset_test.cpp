// SPDX-License-Identifier: Apache-2.0
// NdfAsset and the C API's asset information: kind, map size and wrap, footprint ranges, metadata
// JSON, the library version, and open failures carrying the validator's message id and text. Runs
// on the frozen containers of tests/format, so it needs nothing but the runtime.
#include <glintbake/format/validate.h>
#include <glintbake/runtime/glintbake_ndf_c.h>
#include <glintbake/runtime/ndf_asset.h>
#include <glintbake/runtime/version.h>

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace glintbake::runtime {
namespace {

std::string frozenPath(const char* name) { return std::string(GLINTBAKE_TEST_DATA_DIR) + "/../../format/" + name; }

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

TEST(RuntimeVersion, LibraryMatchesHeaders) {
  const Version v = version();
  EXPECT_EQ(v.major, GLINTBAKE_VERSION_MAJOR);
  EXPECT_EQ(v.minor, GLINTBAKE_VERSION_MINOR);
  EXPECT_EQ(v.patch, GLINTBAKE_VERSION_PATCH);
  EXPECT_STREQ(versionString(), GLINTBAKE_VERSION_STRING);
  EXPECT_TRUE(GLINTBAKE_VERSION_AT_LEAST(0, 1, 0));
  EXPECT_EQ(GLINTBAKE_VERSION, GLINTBAKE_VERSION_MAJOR * 10000 + GLINTBAKE_VERSION_MINOR * 100 + GLINTBAKE_VERSION_PATCH);
  int32_t major = -1, minor = -1, patch = -1;
  gb_version(&major, &minor, &patch);
  EXPECT_EQ(major, v.major);
  EXPECT_EQ(minor, v.minor);
  EXPECT_EQ(patch, v.patch);
  EXPECT_STREQ(gb_version_string(), GLINTBAKE_VERSION_STRING);
}

TEST(NdfAsset, ReportsKindMapRangeAndMetadata) {
  NdfAsset asset;
  OpenError error;
  ASSERT_EQ(asset.open(frozenPath("v1_0_ndf_pyramid.gbk").c_str(), &error), RuntimeStatus::kOk) << error.message;
  EXPECT_EQ(error.status, RuntimeStatus::kOk);
  ASSERT_TRUE(asset.isOpen());
  EXPECT_EQ(asset.kind(), format::AssetKind::kNdfPyramid);
  EXPECT_STREQ(asset.kindName(), "ndf-pyramid");
  const NdfSource& source = *asset.source();
  EXPECT_EQ(source.resolution(), 4);
  EXPECT_EQ(source.mapSize().width, 8);
  EXPECT_EQ(source.mapSize().height, 8);
  EXPECT_EQ(source.wrap(), MapWrap::kRepeat);
  const FootprintRange range = source.footprintRange();
  EXPECT_GT(range.pyramid_min_sigma, 0.0);
  EXPECT_GT(range.pyramid_max_sigma, range.pyramid_min_sigma);
  EXPECT_EQ(range.exact_max_sigma, 0.0);  // no flakes stored
  const std::string meta = asset.metadataJson();
  EXPECT_EQ(meta.size(), asset.metadataSize());
  EXPECT_NE(meta.find("\"asset_kind\""), std::string::npos) << meta;
  EXPECT_NE(meta.find("ndf-pyramid"), std::string::npos) << meta;
  asset.close();
  EXPECT_FALSE(asset.isOpen());
  EXPECT_STREQ(asset.metadataJson(), "");
}

TEST(NdfAsset, MissingFileCarriesTheValidatorsIoMessage) {
  NdfAsset asset;
  OpenError error;
  EXPECT_EQ(asset.open("no-such-dir/missing.gbk", &error), RuntimeStatus::kIoError);
  EXPECT_EQ(error.status, RuntimeStatus::kIoError);
  EXPECT_EQ(error.message_id, 1001);
  EXPECT_GT(std::strlen(error.message), 0u);
  EXPECT_FALSE(asset.isOpen());
}

TEST(NdfAsset, CorruptPayloadCarriesTheValidatorsFirstError) {
  const std::vector<uint8_t> original = readBytes(frozenPath("v1_0_ndf_pyramid.gbk"));
  ASSERT_GT(original.size(), 256u);
  // Corrupts the first byte of one section after another (sections start at multiples of 64 from
  // 128) until the runtime refuses the asset: a section it reads fails its checksum.
  bool refused = false;
  for (size_t at = 128; at + 64 < original.size() && !refused; at += 64) {
    std::vector<uint8_t> bytes = original;
    bytes[at] ^= 0x5a;
    NdfAsset asset;
    OpenError error;
    const RuntimeStatus s = asset.openMemory(bytes.data(), bytes.size(), &error);
    if (s == RuntimeStatus::kOk) continue;
    refused = true;
    const format::ValidationReport report = format::validate(bytes.data(), bytes.size());
    ASSERT_FALSE(report.valid());
    int first_error = 0;
    std::string first_text;
    for (const format::ValidationMessage& m : report.messages)
      if (m.severity == format::Severity::kError) {
        first_error = m.id;
        first_text = m.message;
        break;
      }
    EXPECT_EQ(s, RuntimeStatus::kInvalidAsset);
    EXPECT_EQ(error.status, s);
    EXPECT_EQ(error.message_id, first_error);
    EXPECT_EQ(std::string(error.message), first_text.substr(0, OpenError::kMessageCapacity - 1));
  }
  EXPECT_TRUE(refused);
}

TEST(NdfAsset, NewerMajorVersionIsUnsupportedWithItsId) {
  std::vector<uint8_t> bytes = readBytes(frozenPath("v1_0_ndf_pyramid.gbk"));
  bytes[8] = 9;  // version_major (SPEC.md, header)
  OpenError error;
  std::unique_ptr<NdfSource> source;
  EXPECT_EQ(openNdfAssetMemory(bytes.data(), bytes.size(), &source, &error), RuntimeStatus::kUnsupportedVersion);
  EXPECT_EQ(error.message_id / 1000, 2) << error.message_id << " " << error.message;
  EXPECT_NE(std::string(error.message).find('9'), std::string::npos) << error.message;
}

TEST(NdfAsset, OtherKindIsWrongKindAndSaysWhich) {
  NdfAsset asset;
  OpenError error;
  EXPECT_EQ(asset.open(frozenPath("v1_0_ltc_table.gbk").c_str(), &error), RuntimeStatus::kWrongKind);
  EXPECT_EQ(error.message_id, 0);
  EXPECT_NE(std::string(error.message).find("ltc-table"), std::string::npos) << error.message;
}

TEST(NdfAssetC, InformationAndMetadata) {
  gb_ndf_asset* asset = nullptr;
  gb_open_error error;
  ASSERT_EQ(gb_ndf_asset_open_ex(frozenPath("v1_0_tensor_ndf.gbk").c_str(), &asset, &error), GB_OK) << error.message;
  int32_t kind = 0, resolution = 0;
  ASSERT_EQ(gb_ndf_asset_info(asset, &kind, &resolution), GB_OK);
  EXPECT_EQ(kind, GB_KIND_TENSOR_NDF);
  EXPECT_STREQ(gb_kind_name(kind), "tensor-ndf");
  EXPECT_STREQ(gb_kind_name(GB_KIND_GLITTER), "glitter");
  EXPECT_STREQ(gb_kind_name(-3), "unknown");
  int32_t width = 0, height = 0, wrap = -1;
  EXPECT_EQ(gb_ndf_asset_map(asset, &width, &height, &wrap), GB_OK);
  EXPECT_GT(width, 0);
  EXPECT_GT(height, 0);
  EXPECT_TRUE(wrap == 0 || wrap == 1);
  double exact_max = -1, handover_max = -1, pyramid_min = -1, pyramid_max = -1;
  EXPECT_EQ(gb_ndf_asset_footprint_range(asset, &exact_max, &handover_max, &pyramid_min, &pyramid_max), GB_OK);
  EXPECT_GE(pyramid_max, pyramid_min);
  size_t length = 0;
  ASSERT_EQ(gb_ndf_asset_metadata(asset, nullptr, 0, &length), GB_OK);
  ASSERT_GT(length, 0u);
  std::vector<char> text(length + 1, 'x');
  size_t again = 0;
  ASSERT_EQ(gb_ndf_asset_metadata(asset, text.data(), text.size(), &again), GB_OK);
  EXPECT_EQ(again, length);
  EXPECT_EQ(std::strlen(text.data()), length);
  EXPECT_NE(std::string(text.data()).find("tensor-ndf"), std::string::npos);
  char small[8];
  EXPECT_EQ(gb_ndf_asset_metadata(asset, small, sizeof(small), nullptr), GB_INVALID_ARGUMENT);
  EXPECT_EQ(std::strlen(small), 7u);
  gb_ndf_asset_close(asset);
}

TEST(NdfAssetC, OpenErrors) {
  gb_ndf_asset* asset = reinterpret_cast<gb_ndf_asset*>(&asset);
  gb_open_error error;
  EXPECT_EQ(gb_ndf_asset_open_ex("no-such-dir/missing.gbk", &asset, &error), GB_IO_ERROR);
  EXPECT_EQ(asset, nullptr);
  EXPECT_EQ(error.status, GB_IO_ERROR);
  EXPECT_EQ(error.message_id, 1001);
  EXPECT_GT(std::strlen(error.message), 0u);
  EXPECT_EQ(gb_ndf_asset_open_ex(frozenPath("v1_0_ltc_table.gbk").c_str(), &asset, &error), GB_WRONG_KIND);
  EXPECT_EQ(error.message_id, 0);
  EXPECT_EQ(gb_ndf_asset_open_ex(nullptr, &asset, &error), GB_INVALID_ARGUMENT);
  const char junk[300] = "not a container";
  EXPECT_EQ(gb_ndf_asset_open_memory_ex(junk, sizeof(junk), &asset, &error), GB_INVALID_ASSET);
  EXPECT_GT(error.message_id, 0);
  // Without the error record the plain functions still work.
  EXPECT_EQ(gb_ndf_asset_open("no-such-dir/missing.gbk", &asset), GB_IO_ERROR);
}

}  // namespace
}  // namespace glintbake::runtime
