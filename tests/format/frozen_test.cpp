// SPDX-License-Identifier: Apache-2.0
// Reads the frozen 1.0 containers and checks their exact content (README.md: never regenerated).
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>

#include "frozen_content.h"

#include <gtest/gtest.h>

#include <cstring>

namespace glintbake::format {
namespace {

std::string frozenPath(const char* name) { return std::string(GLINTBAKE_TEST_DATA_DIR) + "/" + name; }

TEST(FrozenV1_0, Minimal) {
  Reader reader;
  ReaderOptions options;
  options.verify_file_checksum = true;
  ASSERT_EQ(reader.open(frozenPath("v1_0_minimal.gbk"), options), ContainerStatus::kOk);
  EXPECT_EQ(reader.header().version_major, 1);
  EXPECT_EQ(reader.header().version_minor, 0);
  EXPECT_EQ(reader.kind(), AssetKind::kTest);
  EXPECT_EQ(reader.header().file_size, 320u);
  ASSERT_EQ(reader.sections().size(), 1u);
  EXPECT_EQ(reader.sections()[0].type, uint32_t(kSectionMetadata));
  EXPECT_EQ(reader.sections()[0].offset, 128u);
  std::string json;
  ASSERT_EQ(reader.readMetadata(&json), ContainerStatus::kOk);
  EXPECT_EQ(json, frozen::minimalMetadata());
  const ValidationReport report = validateFile(frozenPath("v1_0_minimal.gbk"));
  EXPECT_TRUE(report.valid());
  EXPECT_TRUE(report.messages.empty());
}

TEST(FrozenV1_0, Image) {
  const std::string path = frozenPath("v1_0_image.gbk");
  Reader reader;
  ASSERT_EQ(reader.open(path, {kDefaultMaxRawSectionSize, true}), ContainerStatus::kOk);
  EXPECT_EQ(reader.header().version_major, 1);
  EXPECT_EQ(reader.kind(), AssetKind::kTest);
  ASSERT_EQ(reader.sections().size(), 3u);
  EXPECT_EQ(reader.header().file_size, 768u);
  EXPECT_EQ(reader.header().index_offset, 576u);

  const int image = reader.find(kSectionImage, frozen::kImageKey);
  ASSERT_EQ(image, 1);
  const SectionInfo& info = reader.sections()[size_t(image)];
  EXPECT_EQ(info.codec, uint32_t(Codec::kZstd));
  EXPECT_EQ(info.raw_size, 32u + 4 * 4 * 4 * 2);
  std::vector<uint8_t> bytes;
  ASSERT_EQ(reader.readSection(size_t(image), &bytes), ContainerStatus::kOk);
  EXPECT_EQ(bytes, frozen::imageSection());
  ImageSectionHeader header;
  ASSERT_TRUE(parseImageSection(bytes.data(), bytes.size(), &header));
  EXPECT_EQ(header.width, 4u);
  EXPECT_EQ(header.layers, 2u);
  // Spot-check the layout rule (row-major, top row first, layer after layer) on raw floats.
  float v;
  std::memcpy(&v, bytes.data() + 32 + 4 * (16 + 2 * 4 + 3), 4);  // layer 1, row 2, column 3
  EXPECT_EQ(v, frozen::imageValue(3, 2, 1));

  const int raw = reader.find(kSectionFirstPrivate, frozen::kPrivateKey);
  ASSERT_EQ(raw, 2);
  EXPECT_EQ(reader.sections()[size_t(raw)].codec, uint32_t(Codec::kRaw));
  ASSERT_EQ(reader.readSection(size_t(raw), &bytes), ContainerStatus::kOk);
  EXPECT_EQ(bytes, frozen::privateSection());

  std::string json;
  ASSERT_EQ(reader.readMetadata(&json), ContainerStatus::kOk);
  EXPECT_EQ(json, frozen::imageMetadata());
  EXPECT_TRUE(validateFile(path).messages.empty());
}

}  // namespace
}  // namespace glintbake::format
