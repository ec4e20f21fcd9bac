// SPDX-License-Identifier: Apache-2.0
// Normal-map ingest: reads tangent-space normal maps (or height fields) through OpenImageIO and
// turns them into unit normals with a report of what was repaired.
//
// Conventions (formats/SPEC.md, "Coordinates"):
//  - Texel (column c, row r) has its centre at position u = (c + 0.5, r + 0.5) texels; row 0 is the
//    top row of the image file, so position y grows downwards.
//  - The tangent frame of the normals is x = right (increasing column), y = up (decreasing row),
//    z = out of the surface: the OpenGL convention (green up). DirectX maps (green down) need
//    flip_green.
#pragma once

#include <glintbake/bake/result.h>

#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::bake {

enum class Encoding { kAuto, kUnorm, kSnorm };  // auto: float data with negatives is signed, else 2c-1
enum class Wrap { kRepeat, kClamp };

const char* encodingString(Encoding e);  // "auto", "unorm", "snorm"
const char* wrapString(Wrap w);          // "repeat", "clamp"

struct IngestOptions {
  Encoding encoding = Encoding::kAuto;
  bool flip_green = false;  // negate n_y after decoding (DirectX maps)
  // Height field input (first channel, as read: integer files in [0, 1]): normals by central
  // differences with the wrap mode, n = normalize(-k dh/dx, -k dh/dy, 1), where
  // dh/dx = (h[c+1] - h[c-1]) / 2 and dh/dy = (h[r-1] - h[r+1]) / 2 (y up = towards row 0).
  bool height = false;
  double height_scale = 1.0;    // k: slope = height_scale * dh/dtexel, > 0
  Wrap wrap = Wrap::kRepeat;    // how the map continues beyond its edges
  int part = 0;                 // subimage/part of multi-part files (EXR)
  bool fix_nonfinite = false;   // replace NaN/Inf texels by (0,0,1) instead of failing
  int max_size = 16384;         // largest accepted width or height
  double unit_tolerance = 0.1;  // |len - 1| above this counts as "far from unit length"
};

// What ingest found and repaired. Counts are over all texels of the map.
struct IngestReport {
  std::string file_format;  // OIIO format name ("png", "openexr", ...)
  std::string pixel_type;   // "uint8", "uint16", "half", "float", ...
  int channels_in = 0;      // channels of the file (2: XY map with reconstructed z)
  Encoding encoding_used = Encoding::kUnorm;
  int64_t texels = 0;
  int64_t far_from_unit = 0;   // | |n| - 1 | > unit_tolerance before renormalisation
  int64_t nz_nonpositive = 0;  // n_z <= 0 before repair
  int64_t nonfinite = 0;       // NaN or Inf in any channel
  double mean_length = 0.0;    // mean |n| before renormalisation
  std::string content_hash;    // "xxh3-128:..." of the file bytes
};

// A map of unit normals, upper hemisphere (n_z >= 0). Texels with n_z <= 0 keep their projected
// direction (n_x, n_y) and are moved onto the horizon (n_z = 0, |s| = 1); a zero vector becomes
// (0, 0, 1): see normaliseNormals. Plain data: concurrent reads are safe.
struct NormalMap {
  int width = 0;
  int height = 0;
  Wrap wrap = Wrap::kRepeat;
  std::vector<float> normals;  // 3 floats per texel (x, y, z), row-major, row 0 at the top

  const float* at(int x, int y) const { return &normals[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
  float* at(int x, int y) { return &normals[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
  // Texel fetch with the map's wrap mode applied to any int coordinates (repeat: positive
  // modulo; clamp: nearest edge texel). Requires a non-empty map.
  const float* fetch(int x, int y) const;
};

// Reads a normal map (or height field) file. Never throws; errors name the file by the path given,
// on one line, with OIIO's reason where it has one:
//   kIo           the file is missing or unreadable;
//   kInvalidInput not a decodable image, corrupt or truncated data, a size of 0 or above
//                 options.max_size (width or height), an unsupported channel count (2, 3, 4 are
//                 accepted, 1 only with options.height; alpha is ignored), NaN/Inf values without
//                 options.fix_nonfinite (the message gives the count and the first texel);
//   kBadArgument  options.part is negative or beyond the file's parts;
//   kRuntime      out of memory.
// Channels read as float through OIIO: integer files decode as n = 2 c / max - 1; float files
// follow options.encoding (auto: signed if any value is negative). Height fields: see
// IngestOptions::height. Safe on untrusted files as far as OIIO's decoders are: before any pixel
// buffer is allocated, sizes are checked against max_size and the file must be able to hold the
// image its header declares (kInvalidInput otherwise): for codecs of bounded compression ratio
// (PNG; OpenEXR none, RLE, ZIP(S), PXR24, B44(A); TIFF none, PackBits, LZW, deflate) at least
// (decoded bytes - 64 KiB) / ratio bytes of file; for the others the last row (tiled files: the
// last tile) is decoded first, so truncated files fail before the map is allocated. OpenEXR
// headers are walked before OIIO opens the file: every attribute must fit in the file. Decoder messages that libraries
// print on stderr are discarded while reading (the process-wide stderr is redirected briefly), so tools keep their
// one-line errors. Thread-safe for distinct calls, but that redirection is process-wide. `report` may be null; it is
// filled as far as reading got, also on failure.
Result<NormalMap> loadNormalMap(const std::string& path, const IngestOptions& options, IngestReport* report);

// Builds a normal map from raw decoded channel data (for tests and generated maps): `channels` = 2,
// 3 or 4 values per texel already in [-1, 1]; renormalises and repairs like loadNormalMap.
Result<NormalMap> normalMapFromPixels(int width, int height, int channels, const float* data,
                                      const IngestOptions& options, IngestReport* report);

// Renormalises in place, repairs n_z <= 0, counts (used by both entry points above). Non-finite
// texels are an error (kInvalidInput, message with count and first texel) unless
// options.fix_nonfinite, which sets them to (0, 0, 1). Fills texels, far_from_unit, nz_nonpositive,
// nonfinite and mean_length (over finite texels, before renormalisation) of `report` (may be null).
// Multithreaded (TBB); results and counts do not depend on the thread count.
BakeStatus normaliseNormals(NormalMap* map, const IngestOptions& options, IngestReport* report);

// The raw channel values of an image file, for inputs that are not normal maps (a tiny-example
// layout image): width x height x channels floats, row-major, row 0 at the top; integer files read
// as value / max (in [0, 1]), float files as stored.
struct ImageChannels {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> values;
  std::string content_hash;  // "xxh3-128:..." of the file bytes
};

// Reads every channel of an image file with the safety checks of loadNormalMap (sizes checked, the
// file able to hold its declared image, before anything is allocated). Errors, on one line naming
// the file: kIo (missing, unreadable), kInvalidInput (not a decodable image, corrupt or truncated, a
// width or height of 0 or above max_side, more than max_channels channels). Values are not checked.
// Thread-safe for distinct calls (as loadNormalMap, the stderr redirection is process-wide).
Result<ImageChannels> loadImageChannels(const std::string& path, int max_side, int max_channels);

}  // namespace glintbake::bake
