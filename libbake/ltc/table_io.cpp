// SPDX-License-Identifier: Apache-2.0
// Published-layout LTC tables as image files.
#include <glintbake/bake/ltc/table.h>

#include "ltc/exr_writer.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>

namespace glintbake::bake::ltc {

namespace {

constexpr int kMaxImageSize = 1024;

Result<std::vector<float>> readRgba(const std::string& path, int* size) {
  auto input = OIIO::ImageInput::open(path);
  if (!input) return makeError(ErrorCode::kIo, "cannot read " + path + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width != spec.height || spec.width < 2 || spec.width > kMaxImageSize || spec.depth > 1)
    return makeError(ErrorCode::kInvalidInput, path + ": an LTC table image must be square, 2 to 1024 pixels");
  if (spec.nchannels < 4)
    return makeError(ErrorCode::kInvalidInput, path + ": an LTC table image needs 4 channels (RGBA)");
  if (*size != 0 && spec.width != *size)
    return makeError(ErrorCode::kInvalidInput, path + ": the two table images differ in size");
  const int n = spec.width;
  std::vector<float> all(size_t(n) * n * size_t(spec.nchannels));
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    return makeError(ErrorCode::kInvalidInput, "cannot decode " + path + ": " + input->geterror());
  std::vector<float> out(size_t(n) * n * 4);
  for (size_t i = 0; i < size_t(n) * n; ++i) {
    for (int c = 0; c < 4; ++c) {
      const float value = all[i * size_t(spec.nchannels) + size_t(c)];
      if (!std::isfinite(value)) return makeError(ErrorCode::kInvalidInput, path + ": non-finite value in the table");
      out[i * 4 + size_t(c)] = value;
    }
  }
  *size = n;
  return out;
}

}  // namespace

BakeStatus writePublishedExr(const PublishedTable& table, const std::string& prefix) {
  const std::vector<std::string> rgba = {"R", "G", "B", "A"};
  BakeStatus status = writeExr(prefix + "_1.exr", rgba, {table.size, table.size, table.ltc1.data()});
  if (!status.ok()) return status;
  status = writeExr(prefix + "_2.exr", rgba, {table.size, table.size, table.ltc2.data()});
  if (!status.ok()) std::remove((prefix + "_1.exr").c_str());
  return status;
}

Result<PublishedTable> readPublishedImages(const std::string& path1, const std::string& path2) {
  PublishedTable table;
  int size = 0;
  auto ltc1 = readRgba(path1, &size);
  if (!ltc1.ok()) return ltc1.error();
  auto ltc2 = readRgba(path2, &size);
  if (!ltc2.ok()) return ltc2.error();
  table.size = size;
  table.ltc1 = std::move(ltc1).value();
  table.ltc2 = std::move(ltc2).value();
  return table;
}

}  // namespace glintbake::bake::ltc
