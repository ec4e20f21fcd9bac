// SPDX-License-Identifier: Apache-2.0
// Image output through OpenImageIO: atomic (temporary file + rename) and byte-reproducible.
#include <glintbake/bake/io/image_io.h>

#include <glintbake/format/atomic_file.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace glintbake::bake {
namespace {

std::string oneLineWriteError(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? std::string("unknown error") : text;
}

// Formats whose OIIO writers only take 8-bit integers.
bool eightBitOnly(const std::string& ext) {
  return ext == "jpg" || ext == "jpeg" || ext == "webp" || ext == "bmp" || ext == "gif" || ext == "tga";
}

// Quantises [0, 1] values to unsigned integers of `bits` bits, round to nearest, NaN -> 0.
template <typename T>
std::vector<T> quantise(const float* pixels, size_t count, int bits) {
  const double max_level = double((uint32_t(1) << bits) - 1);
  std::vector<T> out(count);
  for (size_t i = 0; i < count; ++i) {
    const float v = pixels[i];
    const double c = std::isnan(v) ? 0.0 : std::clamp(double(v), 0.0, 1.0);
    out[i] = T(std::floor(c * max_level + 0.5));
  }
  return out;
}

}  // namespace

std::string imageExtension(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool isFloatImagePath(const std::string& path) {
  const std::string ext = imageExtension(path);
  return ext == "exr" || ext == "hdr" || ext == "pfm";
}

BakeStatus writeImage(const std::string& path, int width, int height, int channels, const float* pixels,
                      const ImageWriteOptions& options) {
  if (path == "-") {
    return makeError(ErrorCode::kBadArgument,
                     "images cannot be written to standard output ('-'): name a file (.exr, .png, ...)");
  }
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || pixels == nullptr) {
    return makeError(ErrorCode::kBadArgument, path + ": cannot write a " + std::to_string(width) + "x" +
                                                  std::to_string(height) + "x" + std::to_string(channels) + " image");
  }
  if (options.png_bits != 8 && options.png_bits != 16) {
    return makeError(ErrorCode::kBadArgument,
                     path + ": integer bit depth must be 8 or 16, got " + std::to_string(options.png_bits));
  }
  // The plugin is chosen from the final name; the temporary name only receives the bytes.
  auto output = OIIO::ImageOutput::create(path);
  if (!output) {
    return makeError(ErrorCode::kUnsupported,
                     path + ": no image writer for this file extension (" + oneLineWriteError(OIIO::geterror()) + ")");
  }

  const std::string ext = imageExtension(path);
  const bool is_float = isFloatImagePath(path);
  const int bits = eightBitOnly(ext) ? 8 : options.png_bits;
  OIIO::TypeDesc stored = is_float ? (options.half_float ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT)
                                   : (bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  OIIO::ImageSpec spec(width, height, channels, stored);
  if (ext == "exr") spec.attribute("compression", "zip");
  // Values are data, not colours: a fourth channel is stored as given and never divides RGB
  // (OIIO otherwise assumes premultiplied input and un-premultiplies for PNG).
  spec.attribute("oiio:UnassociatedAlpha", 1);
  // OIIO's EXR and TIFF writers stamp the current time when no DateTime is given; an explicit empty
  // value keeps the bytes reproducible (EXR then stores an empty capDate, TIFF no date at all).
  spec.attribute("DateTime", "");
  if (!options.normal_encoding.empty()) spec.attribute(kNormalEncodingAttribute, options.normal_encoding);

  const size_t count = size_t(width) * size_t(height) * size_t(channels);
  std::vector<uint8_t> data8;
  std::vector<uint16_t> data16;
  const void* data = pixels;
  OIIO::TypeDesc data_type = OIIO::TypeDesc::FLOAT;
  if (!is_float) {
    if (bits == 8) {
      data8 = quantise<uint8_t>(pixels, count, 8);
      data = data8.data();
      data_type = OIIO::TypeDesc::UINT8;
    } else {
      data16 = quantise<uint16_t>(pixels, count, 16);
      data = data16.data();
      data_type = OIIO::TypeDesc::UINT16;
    }
  }

  // OIIO encodes into memory; the bytes then reach the disk through one checked write path
  // (format::AtomicFile), so a full disk or a file-size limit can never leave a truncated image
  // that looks complete: OIIO's own file writers do not report every failed write.
  if (!output->supports("ioproxy")) {
    return makeError(ErrorCode::kUnsupported, path + ": this image format cannot be written atomically");
  }
  std::vector<unsigned char> encoded;
  OIIO::Filesystem::IOVecOutput proxy(encoded);
  if (!output->set_ioproxy(&proxy)) {
    return makeError(ErrorCode::kUnsupported, path + ": this image format cannot be written atomically");
  }
  if (!output->open(path, spec)) {
    return makeError(ErrorCode::kIo,
                     path + ": cannot encode the image (" + oneLineWriteError(output->geterror()) + ")");
  }
  const bool written = output->write_image(data_type, data);
  std::string reason = written ? std::string() : oneLineWriteError(output->geterror());
  const bool closed = output->close();
  if (written && !closed) reason = oneLineWriteError(output->geterror());
  output.reset();
  if (!written || !closed) return makeError(ErrorCode::kIo, path + ": write failed (" + reason + ")");
  std::string message;
  if (format::writeFileAtomically(path, encoded.data(), encoded.size(), &message) != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, "cannot write " + message);
  }
  return okStatus();
}

BakeStatus writeNormalMap(const std::string& path, const NormalMap& map, const ImageWriteOptions& options) {
  if (map.width <= 0 || map.height <= 0 || map.normals.size() != size_t(map.width) * size_t(map.height) * 3) {
    return makeError(ErrorCode::kBadArgument, path + ": empty or inconsistent normal map");
  }
  ImageWriteOptions tagged = options;
  if (isFloatImagePath(path)) {
    tagged.normal_encoding = "snorm";
    return writeImage(path, map.width, map.height, 3, map.normals.data(), tagged);
  }
  tagged.normal_encoding = "unorm";
  std::vector<float> encoded(map.normals.size());
  for (size_t i = 0; i < encoded.size(); ++i) encoded[i] = 0.5f * map.normals[i] + 0.5f;
  return writeImage(path, map.width, map.height, 3, encoded.data(), tagged);
}

}  // namespace glintbake::bake
