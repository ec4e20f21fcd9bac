// SPDX-License-Identifier: Apache-2.0
// Private: deterministic float EXR output (no capture date or other run-dependent attributes),
// written atomically (temporary file + rename).
#pragma once

#include <glintbake/bake/result.h>

#include <string>
#include <vector>

namespace glintbake::bake::ltc {

// One image level: width x height x channels float32 values, row-major, top row first.
struct ExrLevel {
  int width = 0;
  int height = 0;
  const float* pixels = nullptr;
};

// Writes a scanline EXR with the given channel names (ZIP compression).
BakeStatus writeExr(const std::string& path, const std::vector<std::string>& channel_names, const ExrLevel& image);

// Writes a tiled, mipmapped EXR (rounding mode up: level l is ceil(w / 2^l) x ceil(h / 2^l)) of one
// channel; `levels` must hold exactly the full chain down to 1 x 1.
BakeStatus writeMipmappedExr(const std::string& path, const std::string& channel_name,
                             const std::vector<ExrLevel>& levels);

}  // namespace glintbake::bake::ltc
