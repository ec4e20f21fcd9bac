// SPDX-License-Identifier: Apache-2.0
// Reading normal maps and height fields from image files through OpenImageIO.
//
// Decoding: integer files store n = 2 c / max - 1; float files are
// either signed ([-1, 1]) or encoded like integers ([0, 1]), told apart by the presence of negative
// values unless the caller forces an encoding. Height fields become normals by central differences
// with the map's wrap mode.
#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/io/normal_map.h>
#include <glintbake/format/container.h>

#include <OpenImageIO/imageio.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#ifndef _WIN32
#include <fcntl.h>
#include <unistd.h>
#endif

namespace glintbake::bake {
namespace {

// Some decoders behind OIIO (libpng's default error handler, for one) print their complaints on
// stderr before OIIO turns them into an error string. Tools promise a single error line, so the
// decoder's own output is discarded while a file is decoded; OIIO's error string carries the reason.
// Not in fuzzing builds: there a sanitizer's or libFuzzer's report of a crash, a timeout or an
// out-of-memory inside a decoder must reach the log.
#if !defined(_WIN32) && !defined(FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION)
#define GLINTBAKE_QUIET_DECODERS 1
#endif
class QuietStderr {
 public:
  QuietStderr() {
#ifdef GLINTBAKE_QUIET_DECODERS
    std::fflush(stderr);
    saved_ = ::dup(STDERR_FILENO);
    const int null_fd = ::open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null_fd >= 0) ::dup2(null_fd, STDERR_FILENO);
    if (null_fd >= 0) ::close(null_fd);
#endif
  }
  ~QuietStderr() {
#ifdef GLINTBAKE_QUIET_DECODERS
    std::fflush(stderr);
    if (saved_ >= 0) {
      ::dup2(saved_, STDERR_FILENO);
      ::close(saved_);
    }
#endif
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  [[maybe_unused]] int saved_ = -1;  // unused where decoders are not silenced
};

// Reading hints: values exactly as stored (no alpha association, which would scale RGB by alpha).
OIIO::ImageSpec readConfig() {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  return config;
}

// OIIO error text can span several lines; tool errors are one line.
std::string oneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? std::string("unknown error") : text;
}

std::string pixelTypeName(const OIIO::TypeDesc& type) {
  switch (type.basetype) {
    case OIIO::TypeDesc::UINT8:
      return "uint8";
    case OIIO::TypeDesc::INT8:
      return "int8";
    case OIIO::TypeDesc::UINT16:
      return "uint16";
    case OIIO::TypeDesc::INT16:
      return "int16";
    case OIIO::TypeDesc::UINT32:
      return "uint32";
    case OIIO::TypeDesc::INT32:
      return "int32";
    case OIIO::TypeDesc::HALF:
      return "half";
    case OIIO::TypeDesc::FLOAT:
      return "float";
    case OIIO::TypeDesc::DOUBLE:
      return "double";
    default:
      return type.c_str();
  }
}

bool isSignedInteger(const OIIO::TypeDesc& type) {
  return type.basetype == OIIO::TypeDesc::INT8 || type.basetype == OIIO::TypeDesc::INT16 ||
         type.basetype == OIIO::TypeDesc::INT32 || type.basetype == OIIO::TypeDesc::INT64;
}

// Normals from a height field: n = normalize(-k dh/dx, -k dh/dy_up, 1) with central differences
// fetched through the wrap mode. Tangent y points up, i.e. towards decreasing rows, hence
// dh/dy_up = (h[r-1] - h[r+1]) / 2. Heights that are not finite were replaced by 0 by the caller.
void heightsToNormals(const std::vector<float>& heights, double k, NormalMap* map) {
  const int w = map->width, h = map->height;
  auto height_at = [&](int x, int y) {
    if (map->wrap == Wrap::kRepeat) {
      x = ((x % w) + w) % w;
      y = ((y % h) + h) % h;
    } else {
      x = std::clamp(x, 0, w - 1);
      y = std::clamp(y, 0, h - 1);
    }
    return double(heights[size_t(y) * size_t(w) + size_t(x)]);
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < w; ++x) {
        const double dhdx = 0.5 * (height_at(x + 1, y) - height_at(x - 1, y));
        const double dhdy_up = 0.5 * (height_at(x, y - 1) - height_at(x, y + 1));
        const double gx = -k * dhdx, gy = -k * dhdy_up;
        const double inv = 1.0 / std::sqrt(gx * gx + gy * gy + 1.0);
        float* n = map->at(x, y);
        n[0] = float(gx * inv);
        n[1] = float(gy * inv);
        n[2] = float(inv);
      }
    }
  });
}

// The one-line reason a header walk gives for a record that claims more bytes than the file has
// left. The name comes from the file: only its printable ASCII reaches the message.
std::string claimsTooMuch(const std::string& what, std::string name, int64_t declared, uint64_t left) {
  for (char& c : name) c = c >= 0x20 && c < 0x7f ? c : '?';
  return what + " '" + name + "' declares " + std::to_string(declared) + " bytes, more than the " +
         std::to_string(left) + " left in the file";
}

// OpenEXR (3.1) allocates every header attribute at the size the file declares before reading it,
// so a 1 KB file can cost gigabytes before OIIO returns. The attributes of every header are walked
// here first, skipping their values: each must lie inside the file. False (and *why) otherwise.
// f stands after the file's first 8 bytes, `start`; size: the file's.
bool exrHeadersFitTheFile(std::istream& f, const unsigned char* start, uint64_t size, std::string* why) {
  const bool multipart = (start[5] & 0x10) != 0;  // version flags bit 12
  auto readName = [&](std::string* out) {
    out->clear();
    for (char c; f.get(c);) {
      if (c == '\0') return true;
      if (out->size() == 255) return false;
      out->push_back(c);
    }
    return false;
  };
  std::string name, type;
  for (int header = 0;; ++header) {
    for (;;) {
      if (!readName(&name)) {
        *why = "truncated OpenEXR header";
        return false;
      }
      if (name.empty()) break;  // end of this header
      unsigned char bytes[4] = {};
      if (!readName(&type) || !f.read(reinterpret_cast<char*>(bytes), 4)) {
        *why = "truncated OpenEXR header";
        return false;
      }
      const int32_t value_size =
          int32_t(uint32_t(bytes[0]) | uint32_t(bytes[1]) << 8 | uint32_t(bytes[2]) << 16 | uint32_t(bytes[3]) << 24);
      const uint64_t at = uint64_t(f.tellg());
      if (value_size < 0 || uint64_t(value_size) > size - std::min(size, at)) {
        *why = claimsTooMuch("OpenEXR attribute", name, value_size, size - std::min(size, at));
        return false;
      }
      f.seekg(std::streamoff(value_size), std::ios::cur);
    }
    if (!multipart) return true;
    // Multi-part files end their list of headers with an empty one.
    const int next = f.peek();
    if (next == std::char_traits<char>::eof()) {
      *why = "truncated OpenEXR header";
      return false;
    }
    if (next == 0) return true;
    if (header > 1 << 16) return true;  // OIIO refuses such part counts itself
  }
}

// libpng allocates each chunk at the length the file declares before reading it (up to 2^31 - 1
// bytes: a 559-byte PNG can ask for 1.9 GB), unless it was built with a chunk size limit. The
// chunks are walked here first, skipping their data: each must lie inside the file, CRC included.
// A file that ends between chunks, before IEND, is left to libpng to refuse. size: the file's.
bool pngChunksFitTheFile(std::istream& f, uint64_t size, std::string* why) {
  for (uint64_t at = 8; at + 8 <= size;) {
    unsigned char head[8] = {};
    if (!f.seekg(std::streamoff(at)) || !f.read(reinterpret_cast<char*>(head), 8)) return true;
    const uint64_t length =
        uint64_t(head[0]) << 24 | uint64_t(head[1]) << 16 | uint64_t(head[2]) << 8 | uint64_t(head[3]);
    const std::string type(reinterpret_cast<const char*>(head + 4), 4);
    const uint64_t left = size - (at + 8);
    if (length + 4 > left) {
      *why = claimsTooMuch("PNG chunk", type, int64_t(length), left < 4 ? 0 : left - 4);
      return false;
    }
    if (type == "IEND") return true;
    at += 12 + length;
  }
  return true;
}

// The PNG header's own bits per pixel (IHDR: bit depth x samples of the colour type; a palette
// index is one sample), or 0 when it cannot be read. f: a PNG file's stream, anywhere.
uint64_t pngBitsPerPixel(std::istream& f) {
  unsigned char ihdr[26] = {};
  if (!f.seekg(0) || !f.read(reinterpret_cast<char*>(ihdr), sizeof(ihdr))) return 0;
  if (std::string(reinterpret_cast<const char*>(ihdr + 12), 4) != "IHDR") return 0;
  const unsigned depth = ihdr[24], colour = ihdr[25];
  const unsigned samples = colour == 0 ? 1 : colour == 2 ? 3 : colour == 3 ? 1 : colour == 4 ? 2 : colour == 6 ? 4 : 0;
  return uint64_t(depth) * samples;
}

// What the checks before decoding learn of a file from their one open: its size (known unless the
// stream could not seek) and, for a PNG, the header's bits per pixel (0 when unreadable).
struct FileFacts {
  bool sized = false;
  uint64_t size = 0;
  uint64_t png_bits = 0;
};

// The checks on a file before any decoder sees it, from one open: kUnreadable when it cannot be
// opened, kRefused (and *why) when its OpenEXR headers or PNG chunks claim more bytes than it
// holds; files of other formats, or too short to tell, are left to OIIO. *facts: what was read.
enum class HeaderWalk { kFits, kUnreadable, kRefused };
HeaderWalk walkHeaders(const std::string& path, std::string* why, FileFacts* facts) {
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static const unsigned char kExr[4] = {0x76, 0x2f, 0x31, 0x01};
  *facts = FileFacts{};
  std::ifstream f(path, std::ios::binary);
  if (!f.good()) return HeaderWalk::kUnreadable;
  // The size of the file this stream has open (not a second lookup of the path).
  if (!f.seekg(0, std::ios::end)) return HeaderWalk::kFits;
  const std::streamoff end = f.tellg();
  if (end < 0 || !f.seekg(0)) return HeaderWalk::kFits;
  facts->sized = true;
  facts->size = uint64_t(end);
  unsigned char start[8] = {};
  if (!f.read(reinterpret_cast<char*>(start), 8)) return HeaderWalk::kFits;
  const bool exr = std::equal(start, start + 4, kExr), png = std::equal(start, start + 8, kPng);
  if (!exr && !png) return HeaderWalk::kFits;
  const bool fits = exr ? exrHeadersFitTheFile(f, start, facts->size, why) : pngChunksFitTheFile(f, facts->size, why);
  if (png && fits) {
    f.clear();
    facts->png_bits = pngBitsPerPixel(f);
  }
  return fits ? HeaderWalk::kFits : HeaderWalk::kRefused;
}

// An opened image and what the checks before decoding read of its file.
struct OpenedImage {
  std::unique_ptr<OIIO::ImageInput> input;
  FileFacts facts;
};

// Opens the image (and the requested part) after the checks that need no decoding.
Result<OpenedImage> openImage(const std::string& path, const IngestOptions& options) {
  if (options.height && !(options.height_scale > 0.0 && std::isfinite(options.height_scale))) {
    return makeError(ErrorCode::kBadArgument, "height scale must be a finite value > 0");
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return makeError(ErrorCode::kIo, path + ": is a directory, not an image file");
  }
  std::string why;
  FileFacts facts;
  switch (walkHeaders(path, &why, &facts)) {
    case HeaderWalk::kUnreadable:
      return makeError(ErrorCode::kIo, path + ": cannot open file for reading");
    case HeaderWalk::kRefused:
      return makeError(ErrorCode::kInvalidInput, path + ": not a readable image (" + why + ")");
    case HeaderWalk::kFits:
      break;
  }
  const OIIO::ImageSpec config = readConfig();
  auto input = OIIO::ImageInput::open(path, &config);
  if (!input) {
    return makeError(ErrorCode::kInvalidInput, path + ": not a readable image (" + oneLine(OIIO::geterror()) + ")");
  }
  if (options.part < 0) {
    return makeError(ErrorCode::kBadArgument, "part must be >= 0, got " + std::to_string(options.part));
  }
  if (options.part > 0 && !input->seek_subimage(options.part, 0)) {
    input->geterror();  // clear
    int parts = 1;
    while (input->seek_subimage(parts, 0)) ++parts;
    input->geterror();
    return makeError(ErrorCode::kBadArgument, path + ": has no part " + std::to_string(options.part) + " (it has " +
                                                  std::to_string(parts) + ")");
  }
  return OpenedImage{std::move(input), facts};
}

// The size and channel checks of the opened part.
BakeStatus checkImageSpec(const std::string& path, const OIIO::ImageSpec& spec, const IngestOptions& options) {
  const int width = spec.width, height = spec.height, channels = spec.nchannels;
  if (spec.deep) {
    return makeError(ErrorCode::kUnsupported, path + ": deep images are not supported");
  }
  if (width <= 0 || height <= 0 || spec.depth > 1) {
    return makeError(ErrorCode::kInvalidInput,
                     path + ": invalid image size " + std::to_string(width) + "x" + std::to_string(height));
  }
  if (width > options.max_size || height > options.max_size) {
    return makeError(ErrorCode::kInvalidInput, path + ": size " + std::to_string(width) + "x" + std::to_string(height) +
                                                   " exceeds the limit of " + std::to_string(options.max_size) +
                                                   " texels per side (raise it with --max-size)");
  }
  if (options.height ? channels < 1 : !(channels >= 2 && channels <= 4)) {
    std::string expected =
        options.height ? "at least 1" : "2 (XY), 3 (RGB) or 4 (RGBA); 1-channel height fields need --height";
    return makeError(ErrorCode::kInvalidInput,
                     path + ": unsupported channel count " + std::to_string(channels) + " (expected " + expected + ")");
  }
  return okStatus();
}

// The smallest number of bytes the decoded samples of the opened part can occupy: every channel of
// the file (all are stored, whatever is read), at the bits per sample the file records (OIIO
// expands 1-, 2- and 4-bit samples to uint8).
uint64_t storedSampleBytes(const OIIO::ImageSpec& spec) {
  const uint64_t texels = uint64_t(spec.width) * uint64_t(spec.height);
  uint64_t bits_per_texel = 0;
  for (int c = 0; c < spec.nchannels; ++c) bits_per_texel += uint64_t(spec.channelformat(c).size()) * 8;
  const int recorded = spec.get_int_attribute("oiio:BitsPerSample", 0);
  if (recorded > 0 && recorded < int(spec.format.size()) * 8) bits_per_texel = uint64_t(recorded) * spec.nchannels;
  return texels / 8 * bits_per_texel + (texels % 8) * bits_per_texel / 8;
}

// How many decoded bytes one byte of the file can produce at most, for the codecs whose ratio is
// bounded (0: unbounded or unknown). Deflate: at most 1032:1 (zlib's documented limit: a 258-byte
// match costs at least 2 bits); OpenEXR RLE and TIFF PackBits: 128 bytes from 2 (64:1); TIFF LZW: a
// 12-bit code names at most 4096 bytes (2731:1); OpenEXR PXR24: deflate of 3 bytes per 4-byte float
// (1376:1); OpenEXR B44/B44A: a flat 4x4 block of 32 bytes in 3 (11:1); no compression: 1:1.
double maxExpansion(const std::string& format, const OIIO::ImageSpec& spec) {
  if (format == "png") return 1032.0;
  std::string codec = spec.get_string_attribute("compression", "none");
  codec = codec.substr(0, codec.find(':'));
  for (char& c : codec) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (format == "openexr") {
    if (codec == "none") return 1.0;
    if (codec == "rle") return 64.0;
    if (codec == "zip" || codec == "zips") return 1032.0;
    if (codec == "pxr24") return 1376.0;
    if (codec == "b44" || codec == "b44a") return 11.0;
    return 0.0;  // piz, dwaa, dwab, htj2k, ...: probed instead
  }
  if (format == "tiff") {
    if (codec == "none") return 1.0;
    if (codec == "packbits") return 64.0;
    if (codec == "lzw") return 2731.0;
    if (codec == "zip" || codec == "deflate" || codec == "adobe_deflate") return 1032.0;
    return 0.0;
  }
  return 0.0;
}

// Refuses, before any pixel buffer is allocated, a file that cannot hold the image its header
// declares (a 74-byte PNG declaring 8192 x 8192 texels): for codecs of bounded ratio, the file must
// have at least (decoded bytes - 64 KiB) / ratio bytes (the slack covers stream ends and is far
// below anything worth refusing); for the others the last row is decoded first, into a one-row
// buffer, so a truncated file or missing chunks fail before the whole image is allocated. The file's
// size and PNG header are the ones read before opening (facts), from the same open as the walk.
BakeStatus checkPlausibleSize(const std::string& path, const OpenedImage& opened, const IngestOptions& options,
                              int used) {
  OIIO::ImageInput& input = *opened.input;
  const OIIO::ImageSpec& spec = input.spec();
  const std::string format = input.format_name();
  if (!opened.facts.sized) return makeError(ErrorCode::kIo, path + ": cannot read the file size");
  const uint64_t file_size = opened.facts.size;
  const double ratio = maxExpansion(format, spec);
  if (ratio > 0.0) {
    uint64_t decoded = storedSampleBytes(spec);
    if (format == "png") {
      const uint64_t bits = opened.facts.png_bits;
      if (bits == 0) return makeError(ErrorCode::kInvalidInput, path + ": unreadable PNG header");
      const uint64_t texels = uint64_t(spec.width) * uint64_t(spec.height);
      decoded = texels / 8 * bits + (texels % 8) * bits / 8;
    }
    constexpr uint64_t kSlack = uint64_t(64) << 10;
    const double needed = decoded > kSlack ? std::ceil(double(decoded - kSlack) / ratio) : 0.0;
    if (double(file_size) < needed) {
      return makeError(ErrorCode::kInvalidInput, path + ": " + std::to_string(file_size) +
                                                     " bytes cannot hold the declared " + std::to_string(spec.width) +
                                                     "x" + std::to_string(spec.height) + " image (" +
                                                     std::to_string(decoded) + " bytes of samples need at least " +
                                                     std::to_string(uint64_t(needed)) + " bytes of file at most " +
                                                     std::to_string(int(ratio)) + ":1)");
    }
    return okStatus();
  }
  // Unbounded codecs: decode the last row (tiled files: the last tile) alone first.
  bool probed = false;
  if (spec.tile_width > 0 && spec.tile_height > 0) {
    const int x0 = spec.x + (spec.width - 1) / spec.tile_width * spec.tile_width;
    const int y0 = spec.y + (spec.height - 1) / spec.tile_height * spec.tile_height;
    const int x1 = spec.x + spec.width, y1 = spec.y + spec.height;
    std::vector<float> tile(size_t(x1 - x0) * size_t(y1 - y0) * size_t(used));
    probed = input.read_tiles(options.part, 0, x0, x1, y0, y1, spec.z, spec.z + 1, 0, used, OIIO::TypeDesc::FLOAT,
                              tile.data());
  } else {
    std::vector<float> row(size_t(spec.width) * size_t(used));
    const int last = spec.y + spec.height - 1;
    probed = input.read_scanlines(options.part, 0, last, last + 1, spec.z, 0, used, OIIO::TypeDesc::FLOAT, row.data());
  }
  if (!probed || input.has_error()) {
    return makeError(ErrorCode::kInvalidInput,
                     path + ": corrupt or truncated image (" + oneLine(input.geterror()) + ")");
  }
  return okStatus();
}

// The first `used` channels of every texel as float.
Result<std::vector<float>> readPixels(const std::string& path, OIIO::ImageInput& input, const IngestOptions& options,
                                      int used) {
  const OIIO::ImageSpec& spec = input.spec();
  const size_t texels = size_t(spec.width) * size_t(spec.height);
  std::vector<float> pixels;
  try {
    pixels.resize(texels * size_t(used));
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, path + ": out of memory reading a " + std::to_string(spec.width) + "x" +
                                              std::to_string(spec.height) + " image");
  }
  if (!input.read_image(options.part, 0, 0, used, OIIO::TypeDesc::FLOAT, pixels.data())) {
    return makeError(ErrorCode::kInvalidInput,
                     path + ": corrupt or truncated image (" + oneLine(input.geterror()) + ")");
  }
  // Some readers report problems only through the error queue.
  if (input.has_error()) {
    return makeError(ErrorCode::kInvalidInput,
                     path + ": corrupt or truncated image (" + oneLine(input.geterror()) + ")");
  }
  input.close();
  return Result<std::vector<float>>(std::move(pixels));
}

// A height field's normals. Non-finite heights would spread into their neighbours' normals; they
// are counted, replaced by 0 when asked, and their own normal is (0,0,1) as for normal maps.
BakeStatus heightsToMap(const std::string& path, std::vector<float>& pixels, const IngestOptions& options,
                        NormalMap* map, IngestReport* r) {
  const size_t texels = size_t(map->width) * size_t(map->height);
  std::vector<size_t> bad_texels;
  for (size_t i = 0; i < texels; ++i) {
    if (!std::isfinite(pixels[i])) {
      bad_texels.push_back(i);
      pixels[i] = 0.0f;
    }
  }
  const int64_t bad = int64_t(bad_texels.size());
  const size_t first = bad_texels.empty() ? 0 : bad_texels.front();
  if (bad > 0 && !options.fix_nonfinite) {
    r->nonfinite = bad;
    r->texels = int64_t(texels);
    return makeError(ErrorCode::kInvalidInput,
                     path + ": " + std::to_string(bad) + " height(s) hold NaN or Inf, the first at column " +
                         std::to_string(first % size_t(map->width)) + ", row " +
                         std::to_string(first / size_t(map->width)) + " (--fix-nonfinite replaces them)");
  }
  heightsToNormals(pixels, options.height_scale, map);
  for (size_t i : bad_texels) {
    map->normals[i * 3 + 0] = 0.0f;
    map->normals[i * 3 + 1] = 0.0f;
    map->normals[i * 3 + 2] = 1.0f;
  }
  r->encoding_used = Encoding::kUnorm;
  BakeStatus status = normaliseNormals(map, options, r);
  if (!status) return makeError(status.error().code, path + ": " + status.error().message);
  r->nonfinite = bad;
  return okStatus();
}

// How stored values map to [-1, 1]: the option, else the encoding the writer recorded (glintbake's
// own maps do), else signed floats or signed integer types are snorm and everything else unorm.
Encoding chooseEncoding(const OIIO::ImageSpec& spec, const std::vector<float>& pixels, Encoding requested) {
  if (requested != Encoding::kAuto) return requested;
  const std::string recorded = spec.get_string_attribute(kNormalEncodingAttribute);
  if (recorded == "snorm" || recorded == "unorm") return recorded == "snorm" ? Encoding::kSnorm : Encoding::kUnorm;
  if (spec.format.is_floating_point()) {
    const bool any_negative = std::any_of(pixels.begin(), pixels.end(), [](float v) { return v < 0.0f; });
    return any_negative ? Encoding::kSnorm : Encoding::kUnorm;
  }
  // OIIO already maps signed integer types to [-1, 1].
  return isSignedInteger(spec.format) ? Encoding::kSnorm : Encoding::kUnorm;
}

// A normal map's normals from `used` stored channels (2: z reconstructed).
BakeStatus pixelsToMap(const std::string& path, const OIIO::ImageSpec& spec, const std::vector<float>& pixels, int used,
                       const IngestOptions& options, NormalMap* map, IngestReport* r) {
  const Encoding encoding = chooseEncoding(spec, pixels, options.encoding);
  r->encoding_used = encoding;
  const float scale = encoding == Encoding::kUnorm ? 2.0f : 1.0f;
  const float offset = encoding == Encoding::kUnorm ? -1.0f : 0.0f;
  const float sign_y = options.flip_green ? -1.0f : 1.0f;
  const size_t texels = size_t(map->width) * size_t(map->height);
  for (size_t i = 0; i < texels; ++i) {
    const float* p = &pixels[i * size_t(used)];
    float* n = &map->normals[i * 3];
    n[0] = scale * p[0] + offset;
    n[1] = sign_y * (scale * p[1] + offset);
    if (used == 2) {
      const float r2 = n[0] * n[0] + n[1] * n[1];
      n[2] = std::isfinite(r2) ? std::sqrt(std::max(0.0f, 1.0f - r2)) : r2;
    } else {
      n[2] = scale * p[2] + offset;
    }
  }
  BakeStatus status = normaliseNormals(map, options, r);
  if (!status) return makeError(status.error().code, path + ": " + status.error().message);
  return okStatus();
}

}  // namespace

Result<NormalMap> loadNormalMap(const std::string& path, const IngestOptions& options, IngestReport* report) {
  IngestReport local;
  IngestReport* r = report != nullptr ? report : &local;
  *r = IngestReport{};

  QuietStderr quiet;
  Result<OpenedImage> opened = openImage(path, options);
  if (!opened) return opened.error();
  OIIO::ImageInput& input = *opened.value().input;
  const OIIO::ImageSpec spec = input.spec();
  r->file_format = input.format_name();
  r->pixel_type = pixelTypeName(spec.format);
  r->channels_in = spec.nchannels;
  if (BakeStatus s = checkImageSpec(path, spec, options); !s) return s.error();

  // Alpha and any extra channels are never read; height fields use the first channel only.
  const int used = options.height ? 1 : std::min(spec.nchannels, 3);
  if (BakeStatus s = checkPlausibleSize(path, opened.value(), options, used); !s) return s.error();
  Result<std::vector<float>> read = readPixels(path, input, options, used);
  if (!read) return read.error();
  std::vector<float>& pixels = read.value();

  NormalMap map;
  map.width = spec.width;
  map.height = spec.height;
  map.wrap = options.wrap;
  map.normals.resize(size_t(spec.width) * size_t(spec.height) * 3);
  const BakeStatus decoded = options.height ? heightsToMap(path, pixels, options, &map, r)
                                            : pixelsToMap(path, spec, pixels, used, options, &map, r);
  if (!decoded) return decoded.error();

  std::string hex;
  if (format::hashFile128Hex(path, &hex) != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, path + ": cannot read file to hash it");
  }
  r->content_hash = hex.rfind("xxh3-128:", 0) == 0 ? hex : "xxh3-128:" + hex;
  return map;
}

Result<ImageChannels> loadImageChannels(const std::string& path, int max_side, int max_channels) {
  QuietStderr quiet;
  IngestOptions options;
  options.max_size = max_side;
  Result<OpenedImage> opened = openImage(path, options);
  if (!opened) return opened.error();
  OIIO::ImageInput& input = *opened.value().input;
  const OIIO::ImageSpec spec = input.spec();
  if (spec.deep) return makeError(ErrorCode::kInvalidInput, path + ": deep images are not supported");
  if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1 || spec.width > max_side || spec.height > max_side) {
    return makeError(ErrorCode::kInvalidInput, path + ": size " + std::to_string(spec.width) + "x" +
                                                   std::to_string(spec.height) + " is outside 1.." +
                                                   std::to_string(max_side) + " per side");
  }
  if (spec.nchannels < 1 || spec.nchannels > max_channels) {
    return makeError(ErrorCode::kInvalidInput, path + ": " + std::to_string(spec.nchannels) + " channels, at most " +
                                                   std::to_string(max_channels) + " expected");
  }
  if (BakeStatus st = checkPlausibleSize(path, opened.value(), options, spec.nchannels); !st) return st.error();
  Result<std::vector<float>> read = readPixels(path, input, options, spec.nchannels);
  if (!read) return read.error();
  ImageChannels out;
  out.width = spec.width;
  out.height = spec.height;
  out.channels = spec.nchannels;
  out.values = std::move(read.value());
  std::string hex;
  if (format::hashFile128Hex(path, &hex) != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, path + ": cannot read file to hash it");
  }
  out.content_hash = hex.rfind("xxh3-128:", 0) == 0 ? hex : "xxh3-128:" + hex;
  return out;
}

}  // namespace glintbake::bake
