// SPDX-License-Identifier: Apache-2.0
// Image output through OpenImageIO, atomically (format::AtomicFile).
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/result.h>

#include <string>

namespace glintbake::bake {

struct ImageWriteOptions {
  // For integer formats (PNG): 8 or 16 bits; values are clamped to [0,1] and quantised. Float
  // formats (EXR) always store float32 (or half if half_float).
  int png_bits = 16;
  bool half_float = false;
  // When non-empty, stored as the file attribute kNormalEncodingAttribute ("snorm" or "unorm"), so
  // that --encoding auto reads the map back as written even when no value is negative (a flat
  // signed map would otherwise look encoded).
  std::string normal_encoding;
};

// Name of the image attribute that records how a normal map's values are encoded.
constexpr const char* kNormalEncodingAttribute = "glintbake:normal_encoding";

// Writes width x height x channels float32 pixels (row-major, top row first) to path; the format
// follows the extension (.exr, .png, .tif, ...). The file appears only when complete.
//
// Float formats (.exr, .hdr, .pfm) store the values as given (float32, or half when half_float).
// Every other format stores unsigned integers of png_bits bits (8 for formats that only hold 8,
// e.g. JPEG): each value is clamped to [0, 1] (NaN becomes 0) and rounded to the nearest level.
// The image is encoded in memory and written through format::AtomicFile: it appears at path only
// when every byte reached the file, and on failure (full disk, file-size limit) nothing is left
// behind and an existing file at path is kept. Bytes depend only on the arguments: no timestamps, host or
// software names are written. Thread-safe (distinct paths). Errors: kBadArgument (bad sizes,
// channels not in 1..4, png_bits not 8 or 16), kUnsupported (unknown extension), kIo.
BakeStatus writeImage(const std::string& path, int width, int height, int channels, const float* pixels,
                      const ImageWriteOptions& options = {});

// Writes a normal map as an image a renderer or this library can read back:
//  - float formats (.exr, ...): signed RGB = (n_x, n_y, n_z) as stored (loadNormalMap's auto
//    encoding detects them as signed whenever any component is negative);
//  - integer formats (.png, .tif, ...): RGB = (n + 1) / 2 quantised to png_bits (16 by default).
// Same atomicity, determinism and errors as writeImage.
BakeStatus writeNormalMap(const std::string& path, const NormalMap& map, const ImageWriteOptions& options = {});

// True when writeImage stores float values for this path's extension (.exr, .hdr, .pfm).
bool isFloatImagePath(const std::string& path);

// The file extension of path in lower case, without the dot ("" when there is none).
std::string imageExtension(const std::string& path);

}  // namespace glintbake::bake
