// SPDX-License-Identifier: Apache-2.0
// Image output: values survive a round trip, files appear atomically, bytes are reproducible.
#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/io/normal_map.h>

#include "../file_size_limit.h"
#include "test_support.h"

#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

namespace glintbake::bake {
namespace {

using test::ScratchDir;

std::vector<float> ramp(int width, int height, int channels) {
  std::vector<float> px(size_t(width) * height * size_t(channels));
  for (size_t i = 0; i < px.size(); ++i) px[i] = float(std::fmod(double(i) * 0.0137, 1.0));
  return px;
}

std::vector<float> readBack(const std::string& path, int* width, int* height, int* channels,
                            OIIO::TypeDesc* stored = nullptr) {
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  const OIIO::ImageSpec& spec = in->spec();
  *width = spec.width;
  *height = spec.height;
  *channels = spec.nchannels;
  if (stored) *stored = spec.format;
  std::vector<float> px(size_t(spec.width) * spec.height * size_t(spec.nchannels));
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
  return px;
}

TEST(ImageIo, FloatExrRoundTripsExactly) {
  ScratchDir dir;
  const std::string path = dir.file("img.exr");
  std::vector<float> px = ramp(13, 7, 4);
  px[5] = -2.5f;  // float formats keep any value
  ASSERT_TRUE(writeImage(path, 13, 7, 4, px.data()).ok());
  int w, h, c;
  OIIO::TypeDesc stored;
  std::vector<float> back = readBack(path, &w, &h, &c, &stored);
  EXPECT_EQ(w, 13);
  EXPECT_EQ(h, 7);
  EXPECT_EQ(c, 4);
  EXPECT_EQ(stored, OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(back, px);
}

TEST(ImageIo, HalfExr) {
  ScratchDir dir;
  const std::string path = dir.file("half.exr");
  std::vector<float> px = ramp(8, 8, 3);
  ImageWriteOptions options;
  options.half_float = true;
  ASSERT_TRUE(writeImage(path, 8, 8, 3, px.data(), options).ok());
  int w, h, c;
  OIIO::TypeDesc stored;
  std::vector<float> back = readBack(path, &w, &h, &c, &stored);
  EXPECT_EQ(stored, OIIO::TypeDesc::HALF);
  for (size_t i = 0; i < px.size(); ++i) EXPECT_NEAR(back[i], px[i], 1e-3);
}

TEST(ImageIo, PngQuantisesWithClampAndRounding) {
  ScratchDir dir;
  for (int bits : {8, 16}) {
    const std::string path = dir.file("q" + std::to_string(bits) + ".png");
    std::vector<float> px = ramp(9, 5, 3);
    px[0] = -1.0f;
    px[1] = 7.0f;
    px[2] = std::nanf("");
    ImageWriteOptions options;
    options.png_bits = bits;
    ASSERT_TRUE(writeImage(path, 9, 5, 3, px.data(), options).ok());
    int w, h, c;
    OIIO::TypeDesc stored;
    std::vector<float> back = readBack(path, &w, &h, &c, &stored);
    EXPECT_EQ(stored, bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
    const double max_level = double((1 << bits) - 1);
    EXPECT_EQ(back[0], 0.0f);
    EXPECT_EQ(back[1], 1.0f);
    EXPECT_EQ(back[2], 0.0f);
    for (size_t i = 3; i < px.size(); ++i) {
      EXPECT_NEAR(back[i], std::floor(px[i] * max_level + 0.5) / max_level, 1e-7) << i;
    }
  }
}

TEST(ImageIo, FourChannelsAreStoredAsGiven) {
  ScratchDir dir;
  std::vector<float> px(4 * 4 * 4);
  for (size_t i = 0; i < px.size(); ++i) px[i] = (i % 4 == 3) ? 0.5f : 0.2f;
  for (const char* name : {"rgba.png", "rgba.exr"}) {
    ASSERT_TRUE(writeImage(dir.file(name), 4, 4, 4, px.data()).ok());
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(dir.file(name), &config);
    ASSERT_TRUE(in);
    std::vector<float> back(px.size());
    ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, back.data()));
    for (size_t i = 0; i < px.size(); ++i) EXPECT_NEAR(back[i], px[i], 1e-4) << name << " " << i;
  }
}

TEST(ImageIo, IdenticalInputsGiveIdenticalBytes) {
  ScratchDir dir;
  std::vector<float> px = ramp(32, 16, 3);
  const char* kExtensions[] = {".exr", ".png", ".tif"};
  for (const char* ext : kExtensions) {
    ASSERT_TRUE(writeImage(dir.file(std::string("a") + ext), 32, 16, 3, px.data()).ok()) << ext;
  }
  // Writers that stamp the time of day would differ after a second.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  for (const char* ext : kExtensions) {
    const std::string a = dir.file(std::string("a") + ext), b = dir.file(std::string("b") + ext);
    ASSERT_TRUE(writeImage(b, 32, 16, 3, px.data()).ok()) << ext;
    const std::string bytes_a = test::readBytes(a), bytes_b = test::readBytes(b);
    EXPECT_FALSE(bytes_a.empty());
    EXPECT_EQ(bytes_a, bytes_b) << ext;
  }
}

TEST(ImageIo, OverwritesAtomicallyAndLeavesNoTemporary) {
  ScratchDir dir;
  const std::string path = dir.file("out.png");
  std::vector<float> px = ramp(4, 4, 3);
  ASSERT_TRUE(writeImage(path, 4, 4, 3, px.data()).ok());
  std::vector<float> px2(px.size(), 0.25f);
  ASSERT_TRUE(writeImage(path, 4, 4, 3, px2.data()).ok());
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.png"});
  int w, h, c;
  std::vector<float> back = readBack(path, &w, &h, &c);
  EXPECT_NEAR(back[0], 0.25f, 1e-4);
}

TEST(ImageIo, FileSizeLimitIsAnIoErrorAndKeepsThePreviousFile) {
  // OIIO's own EXR writer does not notice a failed write; the encoded bytes go through one checked
  // write path instead, so a truncated image never replaces the previous one.
  ScratchDir dir;
  for (const char* name : {"out.exr", "out.png", "out.tif"}) {
    const std::string path = dir.file(name);
    std::vector<float> small = ramp(2, 2, 3);
    ASSERT_TRUE(writeImage(path, 2, 2, 3, small.data()).ok());
    const std::string before = test::readBytes(path);
    std::vector<float> big(256 * 256 * 3);
    for (size_t i = 0; i < big.size(); ++i) big[i] = float((i * 2654435761u) % 1000) / 999.0f;
    BakeStatus status = okStatus();
    {
      test::FileSizeLimit limit(4096);
      status = writeImage(path, 256, 256, 3, big.data());
    }
    ASSERT_FALSE(status.ok()) << name;
    EXPECT_EQ(status.error().code, ErrorCode::kIo);
    EXPECT_NE(status.error().message.find("File too large"), std::string::npos) << status.error().message;
    EXPECT_EQ(test::readBytes(path), before) << name;
  }
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.exr", "out.png", "out.tif"}));
}

TEST(ImageIo, FailuresLeaveNothing) {
  ScratchDir dir;
  std::vector<float> px = ramp(4, 4, 3);
  auto missing_dir = writeImage(dir.file("no/such/dir/out.exr"), 4, 4, 3, px.data());
  ASSERT_FALSE(missing_dir.ok());
  EXPECT_EQ(missing_dir.error().code, ErrorCode::kIo);
  EXPECT_EQ(missing_dir.error().message.find('\n'), std::string::npos);

  auto unknown = writeImage(dir.file("out.notaformat"), 4, 4, 3, px.data());
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kUnsupported);

  auto bad_size = writeImage(dir.file("out.exr"), 0, 4, 3, px.data());
  ASSERT_FALSE(bad_size.ok());
  EXPECT_EQ(bad_size.error().code, ErrorCode::kBadArgument);

  ImageWriteOptions bad_bits;
  bad_bits.png_bits = 12;
  EXPECT_EQ(writeImage(dir.file("out.png"), 4, 4, 3, px.data(), bad_bits).error().code, ErrorCode::kBadArgument);
  EXPECT_TRUE(dir.entries().empty());
}

NormalMap tiltedMap() {
  NormalMap map;
  map.width = 16;
  map.height = 8;
  map.normals.resize(16 * 8 * 3);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 16; ++x) {
      const double a = 0.3 * x, t = 0.05 * (x + y);
      float* n = map.at(x, y);
      n[0] = float(std::sin(t) * std::cos(a));
      n[1] = float(std::sin(t) * std::sin(a));
      n[2] = float(std::cos(t));
    }
  }
  return map;
}

TEST(ImageIo, NormalMapRoundTripThroughIngest) {
  ScratchDir dir;
  const NormalMap map = tiltedMap();
  for (const char* name : {"n.exr", "n.png"}) {
    const std::string path = dir.file(name);
    ASSERT_TRUE(writeNormalMap(path, map).ok()) << name;
    IngestReport report;
    auto back = loadNormalMap(path, IngestOptions{}, &report);
    ASSERT_TRUE(back.ok()) << back.error().message;
    const bool is_exr = std::string(name) == "n.exr";
    EXPECT_EQ(report.encoding_used, is_exr ? Encoding::kSnorm : Encoding::kUnorm);
    for (size_t i = 0; i < map.normals.size(); ++i) {
      EXPECT_NEAR(back.value().normals[i], map.normals[i], is_exr ? 1e-6 : 5e-5) << name << " " << i;
    }
  }
}

// A signed map without a single negative value (flat, or tilted only towards +x+y) would read back
// as encoded under --encoding auto; the recorded encoding attribute keeps it signed.
TEST(ImageIo, FlatSignedMapReadsBackFlat) {
  ScratchDir dir;
  NormalMap flat;
  flat.width = flat.height = 4;
  flat.normals.assign(4 * 4 * 3, 0.0f);
  for (size_t i = 2; i < flat.normals.size(); i += 3) flat.normals[i] = 1.0f;
  for (const char* name : {"flat.exr", "flat.png"}) {
    const std::string path = dir.file(name);
    ASSERT_TRUE(writeNormalMap(path, flat).ok()) << name;
    IngestReport report;
    auto back = loadNormalMap(path, IngestOptions{}, &report);
    ASSERT_TRUE(back.ok()) << back.error().message;
    for (size_t i = 0; i < flat.normals.size(); ++i)
      EXPECT_NEAR(back.value().normals[i], flat.normals[i], 5e-5) << name;
  }
}

}  // namespace
}  // namespace glintbake::bake
