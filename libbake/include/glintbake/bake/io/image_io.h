// Image output through OpenImageIO, atomically (temporary file + rename).
#pragma once

#include <glintbake/bake/result.h>

#include <string>

namespace glintbake::bake {

struct ImageWriteOptions {
  // For integer formats (PNG): 8 or 16 bits; values are clamped to [0,1] and quantised. Float
  // formats (EXR) always store float32 (or half if half_float).
  int png_bits = 16;
  bool half_float = false;
};

// Writes width x height x channels float32 pixels (row-major, top row first) to path; the format
// follows the extension (.exr, .png, .tif, ...). The file appears only when complete.
Status writeImage(const std::string& path, int width, int height, int channels, const float* pixels,
                  const ImageWriteOptions& options = {});

}  // namespace glintbake::bake
