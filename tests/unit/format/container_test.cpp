// SPDX-License-Identifier: Apache-2.0
// Writer/Reader round trips, streaming, random access, codecs and temporary-file handling.
#include <glintbake/format/container.h>

#include "test_files.h"

#include <gtest/gtest.h>

#include <cstring>
#include <thread>

namespace glintbake::format {
namespace {

using test::ScratchDir;

TEST(Container, RoundTripBothCodecs) {
  ScratchDir dir;
  const std::string path = dir.path("a.gbk");
  const auto ramp = test::rampBytes(10000);
  const auto noise = test::noiseBytes(777, 1);
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest, 5), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 1, ramp.data(), ramp.size(), Codec::kZstd), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 2, noise.data(), noise.size(), Codec::kRaw), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  Reader reader;
  ASSERT_EQ(reader.open(path, {0xFFFFFFFF, true}), ContainerStatus::kOk);
  EXPECT_EQ(reader.kind(), AssetKind::kTest);
  EXPECT_EQ(reader.header().version_major, kFormatVersionMajor);
  EXPECT_EQ(reader.header().version_minor, kFormatVersionMinor);
  EXPECT_EQ(reader.header().section_count, 3u);
  EXPECT_EQ(reader.header().file_size, test::readFile(path).size());
  ASSERT_EQ(reader.sections().size(), 3u);
  EXPECT_EQ(reader.sections()[0].codec, uint32_t(Codec::kZstd));
  EXPECT_LT(reader.sections()[0].stored_size, ramp.size());
  EXPECT_EQ(reader.sections()[1].codec, uint32_t(Codec::kRaw));
  for (const SectionInfo& s : reader.sections()) EXPECT_EQ(s.offset % kSectionAlignment, 0u);

  std::vector<uint8_t> out;
  ASSERT_EQ(reader.readSection(size_t(reader.find(kSectionImage, 1)), &out), ContainerStatus::kOk);
  EXPECT_EQ(out, ramp);
  ASSERT_EQ(reader.readSection(size_t(reader.find(kSectionImage, 2)), &out), ContainerStatus::kOk);
  EXPECT_EQ(out, noise);
  std::string json;
  ASSERT_EQ(reader.readMetadata(&json), ContainerStatus::kOk);
  EXPECT_EQ(json, test::testMetadata());
  EXPECT_EQ(reader.find(kSectionImage), 0);
  EXPECT_EQ(reader.find(kSectionImage, 3), -1);
  EXPECT_EQ(reader.find(kSectionNdfChunk), -1);
  EXPECT_EQ(reader.verifyFileChecksum(), ContainerStatus::kOk);

  // The same bytes through the in-memory path.
  const auto bytes = test::readFile(path);
  Reader memory;
  ASSERT_EQ(memory.openMemory(bytes.data(), bytes.size()), ContainerStatus::kOk);
  ASSERT_EQ(memory.readSection(0, &out), ContainerStatus::kOk);
  EXPECT_EQ(out, ramp);
}

TEST(Container, IdenticalInputsGiveIdenticalBytes) {
  ScratchDir dir;
  const auto a = test::makeSmallContainer(dir.path("a.gbk"));
  const auto b = test::makeSmallContainer(dir.path("b.gbk"));
  EXPECT_EQ(a, b);
}

TEST(Container, EmptySection) {
  ScratchDir dir;
  test::makeSmallContainer(dir.path("a.gbk"));
  Reader reader;
  ASSERT_EQ(reader.open(dir.path("a.gbk")), ContainerStatus::kOk);
  const int i = reader.find(kSectionFirstPrivate + 2, 0);
  ASSERT_GE(i, 0);
  EXPECT_EQ(reader.sections()[size_t(i)].raw_size, 0u);
  EXPECT_EQ(reader.sections()[size_t(i)].codec, uint32_t(Codec::kRaw));
  std::vector<uint8_t> out(5, 1);
  ASSERT_EQ(reader.readSection(size_t(i), &out), ContainerStatus::kOk);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(reader.readSectionInto(size_t(i), nullptr, 0), ContainerStatus::kOk);
}

TEST(Container, ManySectionsRandomAccess) {
  ScratchDir dir;
  const std::string path = dir.path("many.gbk");
  constexpr int kCount = 500;
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kNdfPyramid, 1), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    for (int i = 0; i < kCount; ++i) {
      const auto bytes = (i % 2) ? test::noiseBytes(size_t(i * 3), uint64_t(i)) : test::rampBytes(size_t(i * 5));
      const uint64_t key = (uint64_t(i % 7) << 32) | uint64_t(i);
      ASSERT_EQ(writer.addSection(kSectionNdfChunk, key, bytes.data(), bytes.size()), ContainerStatus::kOk);
    }
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  Reader reader;
  ASSERT_EQ(reader.open(path), ContainerStatus::kOk);
  EXPECT_EQ(reader.sections().size(), size_t(kCount + 1));
  // Read in a scrambled order, from several threads at once (const methods are thread-safe).
  auto check = [&](int start, bool* ok) {
    std::vector<uint8_t> out;
    for (int n = 0; n < kCount; ++n) {
      const int i = (start + n * 37) % kCount;
      const uint64_t key = (uint64_t(i % 7) << 32) | uint64_t(i);
      const int index = reader.find(kSectionNdfChunk, key);
      const auto expect = (i % 2) ? test::noiseBytes(size_t(i * 3), uint64_t(i)) : test::rampBytes(size_t(i * 5));
      if (index < 0 || reader.readSection(size_t(index), &out) != ContainerStatus::kOk || out != expect) *ok = false;
    }
  };
  bool ok1 = true, ok2 = true;
  std::thread t1(check, 0, &ok1), t2(check, 11, &ok2);
  t1.join();
  t2.join();
  EXPECT_TRUE(ok1);
  EXPECT_TRUE(ok2);
}

TEST(Container, LargeSectionStreams) {
  ScratchDir dir;
  const std::string path = dir.path("large.gbk");
  const size_t kSize = size_t(48) << 20;  // 48 MiB of compressible floats
  std::vector<uint8_t> big(kSize);
  for (size_t i = 0; i < kSize; i += 4) {
    const float v = float(i % 4096) * 0.25f;
    std::memcpy(&big[i], &v, 4);
  }
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest, 1), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    ASSERT_EQ(writer.addSection(kSectionImage, 0, big.data(), big.size()), ContainerStatus::kOk);
    // Written as added: the bytes are in the file before finish().
    EXPECT_GT(writer.bytesWritten(), 128u);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  }
  Reader reader;
  ASSERT_EQ(reader.open(path), ContainerStatus::kOk);
  std::vector<uint8_t> out(kSize);
  ASSERT_EQ(reader.readSectionInto(0 + size_t(reader.find(kSectionImage)), out.data(), out.size()),
            ContainerStatus::kOk);
  EXPECT_TRUE(out == big);
  EXPECT_EQ(reader.readSectionInto(size_t(reader.find(kSectionImage)), out.data(), out.size() - 1),
            ContainerStatus::kInvalidArgument);
}

TEST(Container, IncompressibleFallsBackToRaw) {
  ScratchDir dir;
  const std::string path = dir.path("noise.gbk");
  const auto noise = test::noiseBytes(4096, 9);
  Writer writer;
  ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
  ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
  ASSERT_EQ(writer.addSection(kSectionImage, 0, noise.data(), noise.size(), Codec::kZstd), ContainerStatus::kOk);
  ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
  Reader reader;
  ASSERT_EQ(reader.open(path), ContainerStatus::kOk);
  const SectionInfo& s = reader.sections()[size_t(reader.find(kSectionImage))];
  EXPECT_EQ(s.codec, uint32_t(Codec::kRaw));
  EXPECT_EQ(s.stored_size, s.raw_size);
}

TEST(Container, MetadataRequiredExactlyOnce) {
  ScratchDir dir;
  const std::string path = dir.path("nometa.gbk");
  Writer writer;
  ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
  const auto ramp = test::rampBytes(64);
  ASSERT_EQ(writer.addSection(kSectionImage, 0, ramp.data(), ramp.size()), ContainerStatus::kOk);
  EXPECT_EQ(writer.finish(), ContainerStatus::kInvalidArgument);
  // Nothing left behind: neither the final file nor the temporary.
  EXPECT_TRUE(dir.list().empty());

  Writer twice;
  ASSERT_EQ(twice.open(path, AssetKind::kTest), ContainerStatus::kOk);
  ASSERT_EQ(twice.addMetadata("{}"), ContainerStatus::kOk);
  EXPECT_EQ(twice.addMetadata("{}"), ContainerStatus::kInvalidArgument);
}

TEST(Container, DuplicateTypeAndKeyRefused) {
  ScratchDir dir;
  Writer writer;
  ASSERT_EQ(writer.open(dir.path("dup.gbk"), AssetKind::kTest), ContainerStatus::kOk);
  const auto ramp = test::rampBytes(64);
  ASSERT_EQ(writer.addSection(kSectionImage, 4, ramp.data(), ramp.size()), ContainerStatus::kOk);
  EXPECT_EQ(writer.addSection(kSectionImage, 4, ramp.data(), ramp.size()), ContainerStatus::kInvalidArgument);
  EXPECT_EQ(writer.addSection(kSectionImage, 5, ramp.data(), ramp.size()), ContainerStatus::kOk);
}

TEST(Container, BadArgumentsRefused) {
  ScratchDir dir;
  Writer writer;
  EXPECT_EQ(writer.addMetadata("{}"), ContainerStatus::kInvalidArgument);  // not open
  EXPECT_EQ(writer.open(dir.path("x.gbk"), AssetKind::kTest, 0), ContainerStatus::kInvalidArgument);
  EXPECT_EQ(writer.open(dir.path("x.gbk"), AssetKind::kTest, 20), ContainerStatus::kInvalidArgument);
  ASSERT_EQ(writer.open(dir.path("x.gbk"), AssetKind::kTest), ContainerStatus::kOk);
  EXPECT_EQ(writer.addSection(kSectionImage, 0, nullptr, 3), ContainerStatus::kInvalidArgument);
  EXPECT_EQ(writer.addSection(kSectionImage, 0, "abc", 3, Codec(9)), ContainerStatus::kInvalidArgument);
  Writer nowhere;
  EXPECT_EQ(nowhere.open(dir.path("missing-dir/x.gbk"), AssetKind::kTest), ContainerStatus::kIoError);
}

TEST(Container, TemporaryFileLifecycle) {
  ScratchDir dir;
  const std::string path = dir.path("t.gbk");
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
    // Anonymous (nothing visible), or one named temporary file beside the destination.
    const std::string tmp = writer.temporaryPath();
    if (!tmp.empty()) {
      EXPECT_EQ(tmp.rfind(path + ".tmp-", 0), 0u) << tmp;
    }
    ASSERT_EQ(dir.list().size(), tmp.empty() ? 0u : 1u);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    writer.abort();
    EXPECT_TRUE(dir.list().empty());
    EXPECT_EQ(writer.finish(), ContainerStatus::kInvalidArgument);
  }
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    // Destroyed without finish().
  }
  EXPECT_TRUE(dir.list().empty());
  {
    Writer writer;
    ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
    ASSERT_EQ(writer.addMetadata(test::testMetadata()), ContainerStatus::kOk);
    ASSERT_EQ(writer.finish(), ContainerStatus::kOk);
    EXPECT_TRUE(writer.temporaryPath().empty());
  }
  EXPECT_EQ(dir.list(), std::vector<std::string>{"t.gbk"});
}

TEST(Container, HashesAreStable) {
  // XXH3 reference values (xxHash test vectors for the empty input).
  EXPECT_EQ(hash64("", 0), 0x2D06800538D394C2ull);
  EXPECT_EQ(hash128Hex("", 0), "xxh3-128:99aa06d3014798d86001c324468d497f");
  ScratchDir dir;
  test::writeFile(dir.path("in.bin"), {'a', 'b', 'c'});
  std::string hex;
  ASSERT_EQ(hashFile128Hex(dir.path("in.bin"), &hex), ContainerStatus::kOk);
  EXPECT_EQ(hex, hash128Hex("abc", 3));
  EXPECT_EQ(hashFile128Hex(dir.path("absent.bin"), &hex), ContainerStatus::kIoError);
}

TEST(Container, Names) {
  EXPECT_STREQ(statusString(ContainerStatus::kOk), "ok");
  EXPECT_STREQ(statusString(ContainerStatus(999)), "unknown status");
  EXPECT_STREQ(codecString(Codec::kZstd), "zstd");
  EXPECT_STREQ(codecString(Codec(5)), "unknown");
  for (uint32_t k = 0; k < 0x8000; ++k) {
    const char* name = assetKindString(AssetKind(k));
    AssetKind back;
    if (std::strcmp(name, "unknown") != 0) {
      ASSERT_TRUE(assetKindFromString(name, &back));
      EXPECT_EQ(back, AssetKind(k));
    }
  }
  AssetKind kind;
  EXPECT_TRUE(assetKindFromString("ndf-pyramid", &kind));
  EXPECT_EQ(kind, AssetKind::kNdfPyramid);
  EXPECT_FALSE(assetKindFromString("ndf", &kind));
}

}  // namespace
}  // namespace glintbake::format

namespace glintbake::format {
namespace {

TEST(Container, SectionTypeNames) {
  uint32_t type = 0;
  for (uint32_t t : {uint32_t(kSectionMetadata), uint32_t(kSectionNdfLevel), uint32_t(kSectionNdfChunk),
                     uint32_t(kSectionTensorIndex), uint32_t(kSectionLtcTable), uint32_t(kSectionRoughness),
                     uint32_t(kSectionImage)}) {
    ASSERT_TRUE(sectionTypeFromString(sectionTypeString(t), &type));
    EXPECT_EQ(type, t);
  }
  EXPECT_STREQ(sectionTypeString(kSectionFirstPrivate + 5), "private");
  EXPECT_STREQ(sectionTypeString(2), "unknown");
  EXPECT_TRUE(sectionTypeFromString("17", &type));
  EXPECT_EQ(type, 17u);
  EXPECT_TRUE(sectionTypeFromString("0x10000", &type));
  EXPECT_EQ(type, 0x10000u);
  EXPECT_FALSE(sectionTypeFromString("4294967296", &type));
  EXPECT_FALSE(sectionTypeFromString("0x", &type));
  EXPECT_FALSE(sectionTypeFromString("", &type));
  EXPECT_FALSE(sectionTypeFromString("ndf", &type));
}

}  // namespace
}  // namespace glintbake::format
