// SPDX-License-Identifier: Apache-2.0
// validate(): message ids for each family, metadata hand checks, image-section checks.
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>

#include "test_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace glintbake::format {
namespace {

using test::ScratchDir;

std::vector<int> ids(const std::vector<ValidationMessage>& messages) {
  std::vector<int> out;
  for (const auto& m : messages) out.push_back(m.id);
  return out;
}

bool has(const std::vector<ValidationMessage>& messages, int id) {
  const auto all = ids(messages);
  return std::find(all.begin(), all.end(), id) != all.end();
}

std::vector<int> metadataIds(const std::string& json, AssetKind kind = AssetKind::kTest) {
  std::vector<ValidationMessage> messages;
  validateMetadata(json, kind, &messages);
  return ids(messages);
}

std::vector<uint8_t> imageBytes(uint32_t w, uint32_t h, uint32_t c, uint32_t layers, float fill) {
  ImageSectionHeader header;
  header.width = w;
  header.height = h;
  header.channels = c;
  header.layers = layers;
  std::vector<uint8_t> bytes(sizeof header + size_t(w) * h * c * layers * 4);
  std::memcpy(bytes.data(), &header, sizeof header);  // little-endian host
  for (size_t i = sizeof header; i < bytes.size(); i += 4) std::memcpy(&bytes[i], &fill, 4);
  return bytes;
}

TEST(Validate, GoodContainerHasNoMessages) {
  ScratchDir dir;
  const auto bytes = test::makeSmallContainer(dir.path("a.gbk"));
  const ValidationReport report = validate(bytes.data(), bytes.size());
  EXPECT_TRUE(report.valid());
  EXPECT_EQ(report.status, ContainerStatus::kOk);
  EXPECT_TRUE(report.messages.empty()) << report.messages.at(0).message;
  const ValidationReport from_file = validateFile(dir.path("a.gbk"));
  EXPECT_TRUE(from_file.messages.empty());
}

TEST(Validate, MetadataSchemaChecks) {
  EXPECT_TRUE(metadataIds(test::testMetadata()).empty());
  EXPECT_EQ(metadataIds("{not json"), std::vector<int>{5003});
  EXPECT_EQ(metadataIds("\"\xff\""), std::vector<int>{5003});
  EXPECT_EQ(metadataIds(std::string(1000, '[') + std::string(1000, ']')), std::vector<int>{5003});
  EXPECT_EQ(metadataIds("[1,2]"), std::vector<int>{5004});
  // An empty object misses every required property.
  EXPECT_EQ(metadataIds("{}"), (std::vector<int>{5005, 5006, 5008, 5009, 5010}));

  const std::string base = R"({"schema":"glintbake.container-metadata/1","asset_kind":"test",)"
                           R"("generator":{"tool":"t","version":"1"},"parameters":{},)";
  EXPECT_TRUE(metadataIds(base + R"("inputs":[]})").empty());
  EXPECT_EQ(metadataIds(base + R"("inputs":[]})", AssetKind::kNdfPyramid), std::vector<int>{5007});
  EXPECT_EQ(metadataIds(base + R"("inputs":[{"name":"a.png"}]})"), std::vector<int>{5010});
  EXPECT_EQ(
      metadataIds(base + R"("inputs":[{"name":"dir/a.png","hash":"xxh3-128:00000000000000000000000000000000"}]})"),
      std::vector<int>{5011});
  EXPECT_EQ(metadataIds(base + R"("inputs":[{"name":"a.png","hash":"xxh3-128:0000"}]})"), std::vector<int>{5012});
  EXPECT_EQ(metadataIds(base + R"("inputs":[{"name":"a.png","hash":"xxh3-128:0000000000000000000000000000000G"}]})"),
            std::vector<int>{5012});
  EXPECT_EQ(metadataIds(base + R"("inputs":[],"asset":3})"), std::vector<int>{5013});
  EXPECT_EQ(metadataIds(base + R"("inputs":[],"extra":3})"), std::vector<int>{5015});
  // Absolute paths anywhere are refused (provenance must not leak private paths).
  EXPECT_EQ(metadataIds(base + R"("inputs":[],"asset":{"source":"/home/me/secret.exr"}})"), std::vector<int>{5014});
  EXPECT_EQ(metadataIds(base + R"("inputs":[],"asset":{"list":["C:\\maps\\a.png"]}})"), std::vector<int>{5014});
  EXPECT_TRUE(metadataIds(base + R"("inputs":[],"asset":{"ratio":"1/2","name":"a.png"}})").empty());
}

TEST(Validate, ImageSections) {
  EXPECT_TRUE(parseImageSection(imageBytes(4, 3, 2, 5, 1.f).data(), imageBytes(4, 3, 2, 5, 1.f).size(), nullptr));
  auto bytes = imageBytes(4, 4, 1, 1, 0.5f);
  ImageSectionHeader header;
  ASSERT_TRUE(parseImageSection(bytes.data(), bytes.size(), &header));
  EXPECT_EQ(header.width, 4u);
  EXPECT_FALSE(parseImageSection(bytes.data(), bytes.size() - 4, nullptr));
  EXPECT_FALSE(parseImageSection(bytes.data(), 31, nullptr));
  // Dimensions whose product overflows 64 bits cannot match any size.
  auto huge = imageBytes(1, 1, 1, 1, 0.f);
  for (size_t at : {4u, 8u, 12u, 16u}) std::memset(&huge[at], 0xFF, 4);
  EXPECT_FALSE(parseImageSection(huge.data(), huge.size(), nullptr));

  ScratchDir dir;
  const std::string path = dir.path("img.gbk");
  const auto good = imageBytes(8, 8, 1, 2, 0.25f);
  const auto nan = imageBytes(2, 2, 1, 1, std::numeric_limits<float>::quiet_NaN());
  const std::vector<uint8_t> not_image(40, 7);
  auto wrong_size = imageBytes(2, 2, 1, 1, 1.f);
  wrong_size.resize(wrong_size.size() + 4);
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 0, good.data(), good.size()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 1, nan.data(), nan.size()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 2, not_image.data(), not_image.size()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionNdfChunk, 3, wrong_size.data(), wrong_size.size()), ContainerStatus::kOk);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  const ValidationReport report = validateFile(path);
  EXPECT_FALSE(report.valid());
  EXPECT_EQ(report.status, ContainerStatus::kOk);  // the container itself is sound
  EXPECT_EQ(ids(report.messages), (std::vector<int>{4006, 4004, 4005}));
}

TEST(Validate, MetadataMissingOrBroken) {
  ScratchDir dir;
  const std::string path = dir.path("meta.gbk");
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kNdfPyramid), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(R"({"schema":"glintbake.container-metadata/0"})"), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionFirstPrivate, 1, "{}", 2), ContainerStatus::kOk);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  // Writers refuse a second metadata section, so make one by retyping index entry 1 (SPEC.md:
  // index_offset at header byte 32, entry type at entry byte 0).
  auto bytes = test::readFile(path);
  uint64_t index_offset = 0;
  for (int i = 7; i >= 0; --i) index_offset = (index_offset << 8) | bytes[32 + size_t(i)];
  const size_t entry = size_t(index_offset) + 64;
  bytes[entry] = 1;
  bytes[entry + 1] = bytes[entry + 2] = bytes[entry + 3] = 0;
  test::resealIndex(&bytes);
  const ValidationReport report = validate(bytes.data(), bytes.size());
  EXPECT_FALSE(report.valid());
  EXPECT_TRUE(has(report.messages, 5002));
  EXPECT_TRUE(has(report.messages, 5005));
  EXPECT_TRUE(has(report.messages, 6002));  // an ndf-pyramid without NDF sections
}

TEST(Validate, CorruptSectionReported) {
  ScratchDir dir;
  auto bytes = test::makeSmallContainer(dir.path("a.gbk"));
  // Damage a section's bytes but keep the whole-file checksum consistent: only 4002 remains.
  bytes[256 + 3] ^= 0x40;
  test::resealFile(&bytes);
  const ValidationReport report = validate(bytes.data(), bytes.size());
  EXPECT_EQ(report.status, ContainerStatus::kChecksumMismatch);
  EXPECT_TRUE(has(report.messages, 4002));
  EXPECT_FALSE(has(report.messages, 4001));
  for (const auto& m : report.messages) {
    EXPECT_EQ(m.message.find('\n'), std::string::npos);
    EXPECT_STRNE(severityString(m.severity), "");
  }
}

}  // namespace
}  // namespace glintbake::format
