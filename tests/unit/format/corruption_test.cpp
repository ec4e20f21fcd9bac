// SPDX-License-Identifier: Apache-2.0
// Hostile and damaged containers: every single-byte flip, every truncation, reader limits,
// version rules and hand-crafted inconsistent indexes. Nothing may crash or read out of bounds,
// and nothing damaged may read back as different data without an error.
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>

#include "test_files.h"

#include <gtest/gtest.h>

namespace glintbake::format {
namespace {

using test::ScratchDir;

// Byte offsets from formats/SPEC.md.
constexpr size_t kVersionMajorOffset = 8, kVersionMinorOffset = 10, kSectionCountOffset = 24;
constexpr size_t kIndexOffsetOffset = 32;
constexpr size_t kEntryCodec = 4, kEntryOffset = 16, kEntryRawSize = 32;

uint64_t load64(const std::vector<uint8_t>& b, size_t at) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b[at + size_t(i)];
  return v;
}
void store64(std::vector<uint8_t>* b, size_t at, uint64_t v) {
  for (int i = 0; i < 8; ++i) (*b)[at + size_t(i)] = uint8_t(v >> (8 * i));
}
void store32(std::vector<uint8_t>* b, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + size_t(i)] = uint8_t(v >> (8 * i));
}
size_t entryAt(const std::vector<uint8_t>& b, size_t i) { return size_t(load64(b, kIndexOffsetOffset)) + 64 * i; }

// Reads every section; returns false at the first error, else fills `contents`.
bool readAll(const Reader& reader, std::vector<std::vector<uint8_t>>* contents) {
  contents->clear();
  for (size_t i = 0; i < reader.sections().size(); ++i) {
    std::vector<uint8_t> out;
    if (reader.readSection(i, &out) != ContainerStatus::kOk) return false;
    contents->push_back(std::move(out));
  }
  return true;
}

class Corruption : public ::testing::Test {
 protected:
  void SetUp() override {
    good_ = test::makeSmallContainer(dir_.path("good.gbk"));
    Reader reader;
    ASSERT_EQ(reader.openMemory(good_.data(), good_.size()), ContainerStatus::kOk);
    ASSERT_TRUE(readAll(reader, &good_contents_));
    ASSERT_TRUE(validate(good_.data(), good_.size()).valid());
  }
  ScratchDir dir_;
  std::vector<uint8_t> good_;
  std::vector<std::vector<uint8_t>> good_contents_;
};

TEST_F(Corruption, EveryByteFlipIsDetected) {
  ASSERT_LT(good_.size(), 4096u);  // keep the loop short
  for (size_t at = 0; at < good_.size(); ++at) {
    for (uint8_t mask : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
      std::vector<uint8_t> bad = good_;
      bad[at] ^= mask;
      // The validator covers every byte (header, file and section checksums).
      const ValidationReport report = validate(bad.data(), bad.size());
      EXPECT_FALSE(report.valid()) << "flip of byte " << at << " mask " << int(mask) << " went unnoticed";
      // A reader that skips the whole-file hash either fails or returns the original data.
      Reader reader;
      if (reader.openMemory(bad.data(), bad.size()) == ContainerStatus::kOk) {
        std::vector<std::vector<uint8_t>> contents;
        if (readAll(reader, &contents)) {
          EXPECT_EQ(contents, good_contents_) << "flip of byte " << at << " changed data silently";
        }
        EXPECT_NE(reader.verifyFileChecksum(), ContainerStatus::kOk) << "byte " << at;
      }
      ReaderOptions verify;
      verify.verify_file_checksum = true;
      EXPECT_NE(reader.openMemory(bad.data(), bad.size(), verify), ContainerStatus::kOk) << "byte " << at;
    }
  }
}

TEST_F(Corruption, EveryTruncationIsDetected) {
  for (size_t length = 0; length < good_.size(); ++length) {
    // A fresh copy of exactly `length` bytes, so reading past it is an ASan error, not luck.
    const std::vector<uint8_t> cut(good_.begin(), good_.begin() + std::ptrdiff_t(length));
    Reader reader;
    const ContainerStatus status = reader.openMemory(cut.data(), cut.size());
    // Every prefix starts with the right magic, so each is reported as truncated.
    EXPECT_EQ(status, ContainerStatus::kTruncated) << "length " << length;
    EXPECT_FALSE(validate(cut.data(), cut.size()).valid()) << "length " << length;
  }
  // Through the file path too, for one length in the section area.
  std::vector<uint8_t> cut(good_.begin(), good_.begin() + 200);
  test::writeFile(dir_.path("cut.gbk"), cut);
  Reader reader;
  EXPECT_EQ(reader.open(dir_.path("cut.gbk")), ContainerStatus::kTruncated);
  EXPECT_EQ(validateFile(dir_.path("cut.gbk")).status, ContainerStatus::kTruncated);
}

TEST_F(Corruption, NotAContainer) {
  const std::string text =
      "hello, this is not a container at all, but it is long enough to hold a header....."
      "..................................................";
  Reader reader;
  EXPECT_EQ(reader.openMemory(text.data(), text.size()), ContainerStatus::kBadMagic);
  // The validator says exactly that, and nothing about sections or metadata it cannot see.
  const ValidationReport not_container = validate(text.data(), text.size());
  ASSERT_EQ(not_container.messages.size(), 1u);
  EXPECT_EQ(not_container.messages[0].id, 2002);
  EXPECT_EQ(not_container.status, ContainerStatus::kBadMagic);
  EXPECT_EQ(reader.openMemory(nullptr, 0), ContainerStatus::kTruncated);
  EXPECT_EQ(reader.open(dir_.path("absent.gbk")), ContainerStatus::kIoError);
  EXPECT_EQ(reader.open(dir_.path("")), ContainerStatus::kIoError);  // a directory
  const ValidationReport report = validateFile(dir_.path("absent.gbk"));
  EXPECT_EQ(report.status, ContainerStatus::kIoError);
  ASSERT_EQ(report.messages.size(), 1u);
  EXPECT_EQ(report.messages[0].id, 1001);
}

TEST_F(Corruption, TrailingBytesRefused) {
  std::vector<uint8_t> bad = good_;
  bad.push_back(0);
  Reader reader;
  EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kCorruptHeader);
}

TEST_F(Corruption, RawSizeCap) {
  ReaderOptions options;
  options.max_raw_section_size = 200;  // the small container has a 300-byte section
  Reader reader;
  EXPECT_EQ(reader.openMemory(good_.data(), good_.size(), options), ContainerStatus::kTooLarge);
  ValidateOptions validate_options;
  validate_options.max_raw_section_size = 200;
  const ValidationReport report = validate(good_.data(), good_.size(), validate_options);
  EXPECT_EQ(report.status, ContainerStatus::kTooLarge);
  EXPECT_EQ(report.messages.at(0).id, 3005);
}

TEST_F(Corruption, SectionCountCap) {
  std::vector<uint8_t> bad = good_;
  store32(&bad, kSectionCountOffset, kMaxSectionCount + 1);
  test::resealHeader(&bad);
  Reader reader;
  EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kTooLarge);
}

TEST_F(Corruption, NewerMinorReadsAndSkipsUnknownSections) {
  // A file as a future 1.x writer could make it: a section type and a codec this reader does not know.
  const std::string path = dir_.path("future.gbk");
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    const auto ramp = test::rampBytes(256);
    ASSERT_EQ(writer.addSection(0x2345, 0, ramp.data(), ramp.size(), Codec::kRaw), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage + 1, 0, ramp.data(), ramp.size(), Codec::kRaw), ContainerStatus::kOk);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  std::vector<uint8_t> bytes = test::readFile(path);
  bytes[kVersionMinorOffset] = 7;
  store32(&bytes, entryAt(bytes, 2) + kEntryCodec, 9);  // a codec of "1.7"
  test::resealIndex(&bytes);
  Reader reader;
  ASSERT_EQ(reader.openMemory(bytes.data(), bytes.size()), ContainerStatus::kOk);
  EXPECT_EQ(reader.header().version_minor, 7);
  ASSERT_EQ(reader.sections().size(), 3u);
  EXPECT_EQ(reader.sections()[1].type, 0x2345u);
  std::vector<uint8_t> out;
  EXPECT_EQ(reader.readSection(1, &out), ContainerStatus::kOk);  // unknown type, known codec: readable
  EXPECT_NE(reader.readSection(2, &out), ContainerStatus::kOk);  // unknown codec: refused, not misread
  std::string json;
  EXPECT_EQ(reader.readMetadata(&json), ContainerStatus::kOk);

  const ValidationReport report = validate(bytes.data(), bytes.size());
  EXPECT_TRUE(report.valid());
  std::vector<int> ids;
  for (const auto& m : report.messages) ids.push_back(m.id);
  EXPECT_NE(std::find(ids.begin(), ids.end(), 2014), ids.end());  // newer minor
  EXPECT_NE(std::find(ids.begin(), ids.end(), 3009), ids.end());  // unknown codec
  EXPECT_NE(std::find(ids.begin(), ids.end(), 3011), ids.end());  // unknown type
}

TEST_F(Corruption, NewerMajorRefused) {
  std::vector<uint8_t> bad = good_;
  bad[kVersionMajorOffset] = 2;
  Reader reader;
  // Refused whether or not the header checksum matches: a 2.x header need not follow 1.x rules.
  EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kUnsupportedVersion);
  test::resealHeader(&bad);
  EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kUnsupportedVersion);
  const ValidationReport report = validate(bad.data(), bad.size());
  EXPECT_EQ(report.status, ContainerStatus::kUnsupportedVersion);
  ASSERT_EQ(report.messages.size(), 1u);
  EXPECT_EQ(report.messages.at(0).id, 2003);
}

TEST_F(Corruption, InconsistentIndexRefused) {
  Reader reader;
  {  // zstd frame announcing a different size than the index
    std::vector<uint8_t> bad = good_;
    const size_t e = entryAt(bad, 1);
    ASSERT_EQ(bad[e + kEntryCodec], 1);
    store64(&bad, e + kEntryRawSize, load64(bad, e + kEntryRawSize) + 1);
    test::resealIndex(&bad);
    ASSERT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kOk);
    std::vector<uint8_t> out;
    EXPECT_EQ(reader.readSection(1, &out), ContainerStatus::kDecompressFailed);
    EXPECT_TRUE(out.empty());
    EXPECT_FALSE(validate(bad.data(), bad.size()).valid());
  }
  {  // overlapping sections
    std::vector<uint8_t> bad = good_;
    store64(&bad, entryAt(bad, 2) + kEntryOffset, load64(bad, entryAt(bad, 1) + kEntryOffset));
    test::resealIndex(&bad);
    EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kCorruptIndex);
  }
  {  // misaligned section
    std::vector<uint8_t> bad = good_;
    store64(&bad, entryAt(bad, 1) + kEntryOffset, load64(bad, entryAt(bad, 1) + kEntryOffset) + 8);
    test::resealIndex(&bad);
    EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kCorruptIndex);
  }
  {  // section reaching into the index
    std::vector<uint8_t> bad = good_;
    store64(&bad, entryAt(bad, 2) + kEntryOffset, load64(bad, kIndexOffsetOffset) - 64);
    test::resealIndex(&bad);
    EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kCorruptIndex);
  }
  {  // raw codec whose stored and raw sizes differ
    std::vector<uint8_t> bad = good_;
    store64(&bad, entryAt(bad, 2) + kEntryRawSize, 1u << 20);
    test::resealIndex(&bad);
    EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kCorruptIndex);
  }
  {  // a zstd "bomb": tiny stored size claiming a huge raw size
    std::vector<uint8_t> bad = good_;
    store64(&bad, entryAt(bad, 1) + kEntryRawSize, uint64_t(1) << 40);
    test::resealIndex(&bad);
    EXPECT_EQ(reader.openMemory(bad.data(), bad.size()), ContainerStatus::kTooLarge);
  }
}

}  // namespace
}  // namespace glintbake::format
