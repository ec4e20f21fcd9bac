// SPDX-License-Identifier: Apache-2.0
// The container sections of ltc-table and roughness assets (formats/SPEC.md 10.2, 10.3).
#include <glintbake/bake/ltc/roughness.h>
#include <glintbake/bake/ltc/table.h>
#include <glintbake/format/kinds/ltc_table.h>
#include <glintbake/format/kinds/roughness.h>

#include <cstring>
#include <string>
#include <vector>

namespace glintbake::bake::ltc {
namespace {

// One image section (SPEC 3.1) of width x height x channels floats, zstd-compressed when smaller.
BakeStatus addImage(format::Writer& writer, uint32_t type, uint64_t key, int width, int height, uint32_t channels,
                    const float* values) {
  format::ImageSectionHeader header;
  header.width = uint32_t(width);
  header.height = uint32_t(height);
  header.channels = channels;
  header.layers = 1;
  const size_t count = size_t(width) * size_t(height) * channels;
  std::vector<uint8_t> bytes(sizeof(header) + count * sizeof(float));
  std::memcpy(bytes.data(), &header, sizeof(header));
  std::memcpy(bytes.data() + sizeof(header), values, count * sizeof(float));
  if (format::ContainerStatus st = writer.addSection(type, key, bytes.data(), bytes.size());
      st != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, std::string("cannot write section ") + format::sectionTypeString(type) + " " +
                                         std::to_string(key) + ": " + writer.errorString(st));
  }
  return okStatus();
}

}  // namespace

BakeStatus writeLtcTableSections(const PublishedTable& table, format::Writer& writer) {
  if (BakeStatus s = addImage(writer, format::kSectionLtcTable, format::kLtcTableKeyMatrix, table.size, table.size,
                              format::kLtcTableChannels, table.ltc1.data());
      !s)
    return s;
  return addImage(writer, format::kSectionLtcTable, format::kLtcTableKeyAmplitude, table.size, table.size,
                  format::kLtcTableChannels, table.ltc2.data());
}

BakeStatus writeRoughnessSections(const std::vector<RoughnessLevel>& levels, format::Writer& writer) {
  for (size_t i = 0; i < levels.size(); ++i) {
    if (BakeStatus s = addImage(writer, format::kSectionRoughness, uint64_t(i), levels[i].width, levels[i].height,
                                format::kRoughnessChannels, levels[i].alpha.data());
        !s)
      return s;
  }
  return okStatus();
}

}  // namespace glintbake::bake::ltc
