// SPDX-License-Identifier: Apache-2.0
// The exact content of the frozen version-1.0 containers in this directory. Shared by the
// generator (run once, by hand, when the files were created) and by frozen_test.cpp.
#pragma once

#include <glintbake/format/container.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace glintbake::format::frozen {

inline std::string minimalMetadata() {
  return R"({"schema":"glintbake.container-metadata/1","asset_kind":"test",)"
         R"("generator":{"tool":"frozen","version":"1.0"},"parameters":{},"inputs":[]})";
}

inline std::string imageMetadata() {
  return R"({"schema":"glintbake.container-metadata/1","asset_kind":"test",)"
         R"("generator":{"tool":"frozen","version":"1.0"},"parameters":{"resolution":4},)"
         R"("inputs":[{"name":"bumps.png","hash":"xxh3-128:00112233445566778899aabbccddeeff"}],)"
         R"("asset":{"note":"frozen v1.0 image container"}})";
}

constexpr uint32_t kImageWidth = 4, kImageHeight = 4, kImageChannels = 1, kImageLayers = 2;

// Value of texel (x, y) of a layer: exact in float32.
inline float imageValue(uint32_t x, uint32_t y, uint32_t layer) {
  return float(x) * 0.5f + float(y) * 0.25f + float(layer);
}

// kSectionImage payload: ImageSectionHeader followed by the float32 values, little-endian.
inline std::vector<uint8_t> imageSection() {
  ImageSectionHeader header;
  header.width = kImageWidth;
  header.height = kImageHeight;
  header.channels = kImageChannels;
  header.layers = kImageLayers;
  std::vector<uint8_t> bytes(sizeof header + 4 * kImageWidth * kImageHeight * kImageLayers);
  std::memcpy(bytes.data(), &header, sizeof header);
  size_t at = sizeof header;
  for (uint32_t layer = 0; layer < kImageLayers; ++layer) {
    for (uint32_t y = 0; y < kImageHeight; ++y) {
      for (uint32_t x = 0; x < kImageWidth; ++x, at += 4) {
        const float v = imageValue(x, y, layer);
        std::memcpy(&bytes[at], &v, 4);
      }
    }
  }
  return bytes;
}

// A private section stored raw: 40 bytes 0, 3, 6, ...
inline std::vector<uint8_t> privateSection() {
  std::vector<uint8_t> bytes(40);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = uint8_t(i * 3);
  return bytes;
}

constexpr uint64_t kImageKey = 42;
constexpr uint64_t kPrivateKey = (uint64_t(1) << 32) | 7;

}  // namespace glintbake::format::frozen
