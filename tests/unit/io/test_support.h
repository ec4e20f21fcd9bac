// SPDX-License-Identifier: Apache-2.0
// Helpers of the io tests: a scratch directory per test, and raw image writing through OIIO so the
// inputs do not depend on the code under test.
#pragma once

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace glintbake::test {

class ScratchDir {
 public:
  ScratchDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("glintbake-io-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_)) names.push_back(e.path().filename().string());
    return names;
  }

 private:
  std::filesystem::path path_;
};

// Writes `values` (width*height*channels, in the given data type) as `stored` pixels; tiled files
// in tiles of tile_side^2 pixels.
inline void writeRaw(const std::string& path, int width, int height, int channels, OIIO::TypeDesc stored,
                     OIIO::TypeDesc data_type, const void* values, bool tiled = false,
                     const char* compression = nullptr, int tile_side = 16) {
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(width, height, channels, stored);
  spec.attribute("oiio:UnassociatedAlpha", 1);  // store alpha as given, RGB untouched
  if (path.size() > 4 && path.substr(path.size() - 4) == ".jpg") {
    spec.attribute("compression", "jpeg:100");  // near-lossless, full chroma resolution
    spec.attribute("jpeg:subsampling", "4:4:4");
  }
  if (compression) spec.attribute("compression", compression);
  if (tiled) {
    spec.tile_width = tile_side;
    spec.tile_height = tile_side;
  }
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(data_type, values)) << out->geterror();
  ASSERT_TRUE(out->close());
}

inline void writeFloats(const std::string& path, int width, int height, int channels, OIIO::TypeDesc stored,
                        const std::vector<float>& values, bool tiled = false, const char* compression = nullptr,
                        int tile_side = 16) {
  writeRaw(path, width, height, channels, stored, OIIO::TypeDesc::FLOAT, values.data(), tiled, compression, tile_side);
}

inline std::string readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) return {};
  std::string bytes(size_t(f.tellg()), '\0');
  f.seekg(0);
  f.read(bytes.data(), std::streamsize(bytes.size()));
  return bytes;
}

inline void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace glintbake::test
