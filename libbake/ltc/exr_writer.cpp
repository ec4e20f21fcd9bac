// SPDX-License-Identifier: Apache-2.0
// Deterministic EXR output through the OpenEXR library.
#include "ltc/exr_writer.h"

#include <glintbake/format/atomic_file.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <exception>
#include <string>

namespace glintbake::bake::ltc {

namespace {

// The EXR is encoded in memory and reaches the disk through format::AtomicFile, whose every write
// is checked: OpenEXR's file streams can lose a failed write (full disk, file-size limit).
BakeStatus commit(const Imf::StdOSStream& encoded, const std::string& path) {
  const std::string bytes = encoded.str();
  std::string message;
  if (format::writeFileAtomically(path, bytes.data(), bytes.size(), &message) != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, "cannot write " + message);
  }
  return okStatus();
}

}  // namespace

BakeStatus writeExr(const std::string& path, const std::vector<std::string>& channel_names, const ExrLevel& image) {
  Imf::StdOSStream stream;
  const size_t channels = channel_names.size();
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::FrameBuffer frame;
    for (size_t c = 0; c < channels; ++c) {
      header.channels().insert(channel_names[c], Imf::Channel(Imf::FLOAT));
      frame.insert(channel_names[c], Imf::Slice(Imf::FLOAT, (char*)(image.pixels + c), sizeof(float) * channels,
                                                sizeof(float) * channels * size_t(image.width)));
    }
    Imf::OutputFile file(stream, header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    return makeError(ErrorCode::kIo, "cannot write " + path + ": " + e.what());
  }
  return commit(stream, path);
}

BakeStatus writeMipmappedExr(const std::string& path, const std::string& channel_name,
                             const std::vector<ExrLevel>& levels) {
  if (levels.empty()) return makeError(ErrorCode::kBadArgument, "no image levels to write");
  Imf::StdOSStream stream;
  try {
    Imf::Header header(levels[0].width, levels[0].height);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.channels().insert(channel_name, Imf::Channel(Imf::FLOAT));
    header.setTileDescription(Imf::TileDescription(32, 32, Imf::MIPMAP_LEVELS, Imf::ROUND_UP));
    Imf::TiledOutputFile file(stream, header);
    if (file.numLevels() != int(levels.size())) throw std::runtime_error("mip chain length mismatch");
    for (int l = 0; l < file.numLevels(); ++l) {
      const ExrLevel& level = levels[size_t(l)];
      if (file.levelWidth(l) != level.width || file.levelHeight(l) != level.height)
        throw std::runtime_error("mip level size mismatch");
      Imf::FrameBuffer frame;
      frame.insert(channel_name,
                   Imf::Slice(Imf::FLOAT, (char*)level.pixels, sizeof(float), sizeof(float) * size_t(level.width)));
      file.setFrameBuffer(frame);
      file.writeTiles(0, file.numXTiles(l) - 1, 0, file.numYTiles(l) - 1, l);
    }
  } catch (const std::exception& e) {
    return makeError(ErrorCode::kIo, "cannot write " + path + ": " + e.what());
  }
  return commit(stream, path);
}

}  // namespace glintbake::bake::ltc
