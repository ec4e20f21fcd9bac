// SPDX-License-Identifier: Apache-2.0
// Reader::openSectionStream: the same bytes and verdicts as readSection, in any piece sizes, from
// files and memory; and the zstd window limit, which every way of reading a section enforces.
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>

#include "test_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

namespace glintbake::format {
namespace {

using test::ScratchDir;

// Reads section i whole through a stream, `piece` bytes at a time.
ContainerStatus streamWhole(const Reader& reader, size_t i, size_t piece, std::vector<uint8_t>* out) {
  out->clear();
  SectionStream stream;
  ContainerStatus status = reader.openSectionStream(i, &stream);
  if (status != ContainerStatus::kOk) return status;
  std::vector<uint8_t> buffer(piece);
  while (stream.remaining() > 0) {
    const size_t n = size_t(std::min<uint64_t>(piece, stream.remaining()));
    status = stream.read(buffer.data(), n);
    if (status != ContainerStatus::kOk) return status;
    out->insert(out->end(), buffer.begin(), buffer.begin() + ptrdiff_t(n));
  }
  return ContainerStatus::kOk;
}

// The blocks of a zstd frame (single segment or not) under a new header: no single segment, a
// window of 2^window_log bytes, the same 8-byte content size, no checksum (RFC 8878 3.1.1.1).
std::vector<uint8_t> withWindow(const std::vector<uint8_t>& frame, int window_log) {
  const uint8_t fhd = frame[4];
  const bool single = (fhd >> 5) & 1;
  const size_t dict_bytes[4] = {0, 1, 2, 4};
  const size_t fcs_bytes[4] = {size_t(single ? 1 : 0), 2, 4, 8};
  const size_t fcs = fcs_bytes[fhd >> 6];
  const size_t fcs_at = 5 + (single ? 0 : 1) + dict_bytes[fhd & 3];
  uint64_t content = 0;
  for (size_t k = 0; k < fcs; ++k) content |= uint64_t(frame[fcs_at + k]) << (8 * k);
  if (fcs == 2) content += 256;
  EXPECT_EQ((fhd >> 2) & 1, 0) << "the writer sets no frame checksum";
  std::vector<uint8_t> out(frame.begin(), frame.begin() + 4);
  out.push_back(0xC0);  // 8-byte content size, not single segment, no checksum, no dictionary
  out.push_back(uint8_t((window_log - 10) << 3));
  for (int k = 0; k < 8; ++k) out.push_back(uint8_t(content >> (8 * k)));
  out.insert(out.end(), frame.begin() + ptrdiff_t(fcs_at + fcs), frame.end());
  return out;
}

std::vector<uint8_t> floatBytes(size_t count) {
  std::vector<uint8_t> bytes(count * 4);
  for (size_t i = 0; i < count; ++i) {
    const float v = float((i * 2654435761u) % 1024) * 0.5f;
    std::memcpy(&bytes[4 * i], &v, 4);
  }
  return bytes;
}

TEST(SectionStream, SameBytesAsReadSectionInAnyPieceSize) {
  ScratchDir dir;
  const std::string path = dir.path("s.gbk");
  const auto big = floatBytes(size_t(3) << 20);  // 12 MiB: many stored pieces and decoded pieces
  const auto noise = test::noiseBytes(size_t(2) << 20 | 123, 5);
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest, 3), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 1, big.data(), big.size()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 2, noise.data(), noise.size(), Codec::kRaw), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 3, nullptr, 0), ContainerStatus::kOk);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  const auto file = test::readFile(path);
  Reader from_file, from_memory;
  ASSERT_EQ(from_file.open(path), ContainerStatus::kOk);
  ASSERT_EQ(from_memory.openMemory(file.data(), file.size()), ContainerStatus::kOk);
  for (const Reader* reader : {&from_file, &from_memory}) {
    for (size_t i = 0; i < reader->sections().size(); ++i) {
      std::vector<uint8_t> whole, streamed;
      ASSERT_EQ(reader->readSection(i, &whole), ContainerStatus::kOk);
      for (size_t piece : {size_t(1) << 20, size_t(4093), size_t(1)}) {
        if (piece == 1 && whole.size() > 100000) continue;
        ASSERT_EQ(streamWhole(*reader, i, piece, &streamed), ContainerStatus::kOk) << i << " " << piece;
        EXPECT_TRUE(streamed == whole) << i << " " << piece;
      }
    }
  }
  SectionStream stream;
  EXPECT_EQ(stream.size(), 0u);
  uint8_t byte = 0;
  EXPECT_EQ(stream.read(&byte, 1), ContainerStatus::kInvalidArgument);
  EXPECT_EQ(from_file.openSectionStream(99, &stream), ContainerStatus::kNotFound);
  EXPECT_EQ(from_file.openSectionStream(0, nullptr), ContainerStatus::kInvalidArgument);
}

TEST(SectionStream, DamageFoundByDecodingFailsTheReadThatMeetsIt) {
  ScratchDir dir;
  const std::string path = dir.path("d.gbk");
  const auto big = floatBytes(size_t(1) << 20);
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest, 3), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 1, big.data(), big.size()), ContainerStatus::kOk);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  auto bytes = test::readFile(path);
  Reader reader;
  ASSERT_EQ(reader.openMemory(bytes.data(), bytes.size()), ContainerStatus::kOk);
  const SectionInfo s = reader.sections()[size_t(reader.find(kSectionImage))];
  // Garble the end of the frame's last block, then fix the section and file checksums: only
  // decoding can tell.
  for (size_t k = 1; k <= 16; ++k) bytes[size_t(s.offset + s.stored_size - k)] ^= 0x5A;
  const uint64_t checksum = hash64(bytes.data() + s.offset, size_t(s.stored_size));
  const size_t entry = size_t(reader.header().index_offset) + 64 * size_t(reader.find(kSectionImage));
  for (int k = 0; k < 8; ++k) bytes[entry + 40 + size_t(k)] = uint8_t(checksum >> (8 * k));
  test::resealIndex(&bytes);
  test::resealFile(&bytes);
  ASSERT_EQ(reader.openMemory(bytes.data(), bytes.size()), ContainerStatus::kOk);
  std::vector<uint8_t> out;
  const size_t i = size_t(reader.find(kSectionImage));
  EXPECT_EQ(reader.readSection(i, &out), ContainerStatus::kDecompressFailed);
  EXPECT_EQ(streamWhole(reader, i, 65536, &out), ContainerStatus::kDecompressFailed);
  const ValidationReport report = validate(bytes.data(), bytes.size());
  ASSERT_FALSE(report.valid());
  EXPECT_EQ(report.messages[0].id, 4003);
}

TEST(SectionStream, FramesOfWindowsOverTheLimitAreRefusedByEveryReader) {
  ScratchDir dir;
  const auto data = floatBytes(100000);
  SectionEncoder encoder(9);
  std::vector<uint8_t> frame;
  Codec used = Codec::kRaw;
  ASSERT_EQ(encoder.encode(data.data(), data.size(), Codec::kZstd, &frame, &used), ContainerStatus::kOk);
  ASSERT_EQ(used, Codec::kZstd);
  for (int window_log : {27, 28, 31}) {
    const std::string path = dir.path("w" + std::to_string(window_log) + ".gbk");
    const auto framed = withWindow(frame, window_log);
    {
      Writer writer;
      ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
      ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
      ASSERT_EQ(
          writer.addStoredSection(kSectionFirstPrivate, 1, Codec::kZstd, data.size(), framed.data(), framed.size()),
          ContainerStatus::kOk);
      ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
    }
    const ContainerStatus expected = window_log <= 27 ? ContainerStatus::kOk : ContainerStatus::kTooLarge;
    Reader reader;
    ASSERT_EQ(reader.open(path), ContainerStatus::kOk);
    const size_t i = size_t(reader.find(kSectionFirstPrivate));
    std::vector<uint8_t> out;
    EXPECT_EQ(reader.readSection(i, &out), expected) << window_log;
    EXPECT_EQ(out.empty(), expected != ContainerStatus::kOk);
    if (expected == ContainerStatus::kOk) {
      EXPECT_TRUE(out == data);
    }
    std::vector<uint8_t> into(data.size());
    EXPECT_EQ(reader.readSectionInto(i, into.data(), into.size()), expected) << window_log;
    EXPECT_EQ(streamWhole(reader, i, 4096, &out), expected) << window_log;
    if (expected == ContainerStatus::kOk) {
      EXPECT_TRUE(out == data);
    }
    const ValidationReport report = validateFile(path);
    EXPECT_EQ(report.valid(), expected == ContainerStatus::kOk) << window_log;
    if (!report.valid()) {
      EXPECT_EQ(report.messages[0].id, 4010);
      EXPECT_EQ(report.status, ContainerStatus::kTooLarge);
    }
  }
}

}  // namespace
}  // namespace glintbake::format
