// SPDX-License-Identifier: Apache-2.0
#include "test_files.h"

#include <glintbake/format/container.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace glintbake::format::test {

namespace fs = std::filesystem;

ScratchDir::ScratchDir() {
  std::string pattern = (fs::path(::testing::TempDir()) / "glintbake-format-XXXXXX").string();
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (!::mkdtemp(buffer.data())) ADD_FAILURE() << "cannot create a scratch directory";
  dir_ = buffer.data();
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

std::vector<std::string> ScratchDir::list() const {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<uint8_t> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeFile(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<uint8_t> noiseBytes(size_t size, uint64_t seed) {
  std::vector<uint8_t> bytes(size);
  uint64_t x = seed * 0x9E3779B97F4A7C15ull + 1;
  for (auto& b : bytes) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    b = uint8_t(x >> 32);
  }
  return bytes;
}

std::vector<uint8_t> rampBytes(size_t size) {
  std::vector<uint8_t> bytes(size);
  for (size_t i = 0; i < size; ++i) bytes[i] = uint8_t((i / 7) % 251);
  return bytes;
}

std::string testMetadata() {
  return R"({"schema":"glintbake.container-metadata/1","asset_kind":"test",)"
         R"("generator":{"tool":"format_unit_tests","version":"0.1.0"},"parameters":{"n":1},)"
         R"("inputs":[{"name":"input.png","hash":"xxh3-128:0123456789abcdef0123456789abcdef"}]})";
}

std::vector<uint8_t> makeSmallContainer(const std::string& path) {
  Writer writer;
  EXPECT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
  EXPECT_EQ(writer.addMetadata(testMetadata()), ContainerStatus::kOk);
  const auto ramp = rampBytes(300);
  EXPECT_EQ(writer.addSection(kSectionFirstPrivate, 7, ramp.data(), ramp.size(), Codec::kZstd), ContainerStatus::kOk);
  const auto noise = noiseBytes(100, 3);
  EXPECT_EQ(writer.addSection(kSectionFirstPrivate + 1, 0, noise.data(), noise.size(), Codec::kRaw),
            ContainerStatus::kOk);
  EXPECT_EQ(writer.addSection(kSectionFirstPrivate + 2, 0, nullptr, 0), ContainerStatus::kOk);
  EXPECT_EQ(writer.finish(), ContainerStatus::kOk);
  return readFile(path);
}

namespace {
void store64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = uint8_t(v >> (8 * i));
}
uint64_t load64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
}  // namespace

// Offsets from formats/SPEC.md, "Header".
void resealHeader(std::vector<uint8_t>* bytes) {
  uint8_t* h = bytes->data();
  store64(h + 72, 0);
  store64(h + 72, hash64(h, 128));
}

void resealIndex(std::vector<uint8_t>* bytes) {
  uint8_t* h = bytes->data();
  const uint64_t index_offset = load64(h + 32), index_size = load64(h + 40);
  store64(h + 64, hash64(h + index_offset, size_t(index_size)));
  resealFile(bytes);
}

void resealFile(std::vector<uint8_t>* bytes) {
  uint8_t* h = bytes->data();
  store64(h + 56, hash64(h + 128, bytes->size() - 128));
  resealHeader(bytes);
}

}  // namespace glintbake::format::test
