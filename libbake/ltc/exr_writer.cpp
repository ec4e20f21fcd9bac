// Deterministic EXR output through the OpenEXR library.
#include "ltc/exr_writer.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <unistd.h>
#include <atomic>
#include <cstdio>
#include <exception>

namespace glintbake::bake::ltc {

namespace {

std::string temporaryName(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  char suffix[64];
  std::snprintf(suffix, sizeof(suffix), ".tmp-%ld-%u", long(getpid()), counter.fetch_add(1));
  return path + suffix;
}

BakeStatus commit(const std::string& tmp, const std::string& path) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return makeError(ErrorCode::kIo, "cannot write " + path + ": rename failed");
  }
  return okStatus();
}

}  // namespace

BakeStatus writeExr(const std::string& path, const std::vector<std::string>& channel_names, const ExrLevel& image) {
  const std::string tmp = temporaryName(path);
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
    Imf::OutputFile file(tmp.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    return makeError(ErrorCode::kIo, "cannot write " + path + ": " + e.what());
  }
  return commit(tmp, path);
}

BakeStatus writeMipmappedExr(const std::string& path, const std::string& channel_name,
                             const std::vector<ExrLevel>& levels) {
  if (levels.empty()) return makeError(ErrorCode::kBadArgument, "no image levels to write");
  const std::string tmp = temporaryName(path);
  try {
    Imf::Header header(levels[0].width, levels[0].height);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.channels().insert(channel_name, Imf::Channel(Imf::FLOAT));
    header.setTileDescription(Imf::TileDescription(32, 32, Imf::MIPMAP_LEVELS, Imf::ROUND_UP));
    Imf::TiledOutputFile file(tmp.c_str(), header);
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
    std::remove(tmp.c_str());
    return makeError(ErrorCode::kIo, "cannot write " + path + ": " + e.what());
  }
  return commit(tmp, path);
}

}  // namespace glintbake::bake::ltc
