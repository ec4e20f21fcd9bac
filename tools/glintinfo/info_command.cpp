// SPDX-License-Identifier: Apache-2.0
// glintinfo info: header, section table and metadata of a container.
#include "commands.h"
#include "container_access.h"

#include <glintbake/format/kinds/flakes.h>
#include <glintbake/format/kinds/ndf_pyramid.h>
#include <glintbake/format/kinds/ndf_pyramid_blend.h>

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <iostream>

namespace glintbake::glintinfo {
namespace {

std::string hex64(uint64_t v) {
  char buffer[19];
  std::snprintf(buffer, sizeof buffer, "0x%016" PRIx64, v);
  return buffer;
}

std::string kindLabel(uint32_t kind) {
  const std::string name = format::assetKindString(format::AssetKind(kind));
  return name == "unknown" ? "unknown (" + std::to_string(kind) + ")" : name;
}

// The map and the footprints an NDF asset answers and how (ndf_source.h, FootprintRange), read
// from its level records and its flakes record; null for containers without levels. Records that
// fail their checks are left out (validate names them).
cli::Json footprintSummary(const format::Reader& reader, const std::string& path) {
  format::NdfLevelRecord first, top;
  int levels = 0;
  for (int l = 0; l < format::kMaxNdfLevels; ++l) {
    const int idx = reader.find(format::kSectionNdfLevel, uint64_t(l));
    if (idx < 0 || reader.sections()[size_t(idx)].raw_size != sizeof(format::NdfLevelRecord)) break;
    const auto bytes = readSectionOrThrow(reader, path, size_t(idx));
    format::NdfLevelRecord rec;
    std::memcpy(&rec, bytes.data(), sizeof(rec));
    if (!format::checkNdfLevelRecord(rec, uint32_t(l), levels > 0 ? &top : nullptr)) break;
    if (l == 0) first = rec;
    top = rec;
    ++levels;
  }
  if (levels == 0) return nullptr;
  cli::Json doc;
  doc["map"] = {
      {"width", first.map_width}, {"height", first.map_height}, {"wrap", first.wrap == 0 ? "repeat" : "clamp"}};
  cli::Json fp;
  fp["levels"] = levels;
  fp["pyramid_min_sigma"] = first.sigma_texels;
  fp["pyramid_max_sigma"] = top.sigma_texels;
  fp["exact_max_sigma"] = 0.0;
  fp["handover_max_sigma"] = 0.0;
  fp["clustered_min_sigma"] = 0.0;
  fp["clustered_max_sigma"] = 0.0;
  const int flakes = reader.find(format::kSectionFlakes, 0);
  if (flakes >= 0) {
    const auto bytes = readSectionOrThrow(reader, path, size_t(flakes));
    format::FlakesRecord rec;
    if (bytes.size() >= sizeof(rec)) {
      std::memcpy(&rec, bytes.data(), sizeof(rec));
      if (format::checkFlakesRecord(rec, bytes.size()) == nullptr) {
        fp["exact_max_sigma"] = rec.flakes_up_to;
        fp["handover_max_sigma"] = rec.pyramid_from;
        if (format::hasLobes(rec)) {
          fp["clustered_min_sigma"] = rec.flakes_up_to * format::kLobesBand;
          fp["clustered_max_sigma"] = rec.lobes_up_to;
          fp["lobes_per_tile"] = rec.lobes_per_tile;
          uint32_t milli = format::kDefaultFlakesTileRatioMilli;
          if (format::flakesTileRatio(rec, bytes.data(), bytes.size(), &milli)) fp["lobes_tile_ratio"] = milli / 1000.0;
        }
      }
    }
  }
  // Above the top level: a top grid that fits the blend spreads to any width (repeating or clamped).
  fp["unbounded_above_top"] =
      top.grid_width <= uint32_t(format::kWholeGridAxis) && top.grid_height <= uint32_t(format::kWholeGridAxis);
  doc["footprints"] = fp;
  return doc;
}

}  // namespace

CLI::App* addInfoCommand(CLI::App& app, InfoOptions& options) {
  CLI::App* cmd = app.add_subcommand("info", "Print the header, the section table and the metadata");
  cmd->add_option("file", options.file, "Container file (.gbk)")->required();
  return cmd;
}

int runInfo(cli::Tool& tool, const InfoOptions& options) {
  const auto reader = openContainer(options.file);
  const format::HeaderInfo& header = reader->header();
  const auto& sections = reader->sections();

  // The metadata is shown parsed when it is JSON within the nesting limit, as text otherwise
  // (validate reports why); more than 16 MiB of it is refused before it is decoded.
  const std::string metadata_text = readMetadataOrThrow(*reader, options.file);
  cli::Json metadata = parseMetadata(metadata_text);
  if (metadata.is_null() && !metadata_text.empty()) metadata = metadata_text;

  if (tool.common().json) {
    cli::Json doc;
    doc["file"] = cli::baseName(options.file);
    doc["format_version"] = std::to_string(header.version_major) + "." + std::to_string(header.version_minor);
    doc["asset_kind"] = format::assetKindString(format::AssetKind(header.asset_kind));
    doc["asset_kind_id"] = header.asset_kind;
    doc["file_size"] = header.file_size;
    doc["file_checksum"] = hex64(header.file_checksum);
    doc["section_count"] = header.section_count;
    cli::Json rows = cli::Json::array();
    for (size_t i = 0; i < sections.size(); ++i) {
      const format::SectionInfo& s = sections[i];
      cli::Json row;
      row["index"] = i;
      row["type"] = s.type;
      row["type_name"] = format::sectionTypeString(s.type);
      row["key"] = s.key;
      row["codec"] = format::codecString(format::Codec(s.codec));
      row["offset"] = s.offset;
      row["stored_size"] = s.stored_size;
      row["raw_size"] = s.raw_size;
      row["ratio"] = s.stored_size ? double(s.raw_size) / double(s.stored_size) : 1.0;
      row["checksum"] = hex64(s.checksum);
      rows.push_back(row);
    }
    doc["sections"] = rows;
    doc["metadata"] = metadata;
    if (const cli::Json summary = footprintSummary(*reader, options.file); !summary.is_null()) {
      doc["map"] = summary["map"];
      doc["footprints"] = summary["footprints"];
    }
    tool.printJson(doc);
    return cli::kExitOk;
  }

  std::printf("file:           %s\n", options.file.c_str());
  std::printf("format:         %u.%u\n", header.version_major, header.version_minor);
  std::printf("asset kind:     %s\n", kindLabel(header.asset_kind).c_str());
  std::printf("file size:      %" PRIu64 " bytes\n", header.file_size);
  std::printf("file checksum:  %s (XXH3-64)\n", hex64(header.file_checksum).c_str());
  std::printf("sections:       %u\n", header.section_count);
  if (const cli::Json s = footprintSummary(*reader, options.file); !s.is_null()) {
    const cli::Json& f = s["footprints"];
    std::printf("map:            %d x %d texels, wrap %s\n", s["map"]["width"].get<int>(),
                s["map"]["height"].get<int>(), s["map"]["wrap"].get<std::string>().c_str());
    if (f["exact_max_sigma"].get<double>() > 0.0 && f["clustered_max_sigma"].get<double>() > 0.0) {
      // (A trailer out of range is left out of the JSON; `validate` names it, error 4008.)
      char tiles[64];
      if (f.contains("lobes_tile_ratio"))
        std::snprintf(tiles, sizeof(tiles), "tiles of up to %g sigma", f["lobes_tile_ratio"].get<double>());
      else
        std::snprintf(tiles, sizeof(tiles), "a tile ratio out of range");
      std::printf(
          "footprints:     exact from the flakes for sigma <= %g texels, clustered lobes (%d per tile, %s) from %g to "
          "%g (the runtime bounds them by their window), blended into the pyramid up to %g\n",
          f["exact_max_sigma"].get<double>(), f["lobes_per_tile"].get<int>(), tiles,
          f["clustered_min_sigma"].get<double>(), f["clustered_max_sigma"].get<double>(),
          f["handover_max_sigma"].get<double>());
    } else if (f["exact_max_sigma"].get<double>() > 0.0) {
      std::printf("footprints:     exact from the flakes for sigma <= %g texels, blended into the pyramid up to %g\n",
                  f["exact_max_sigma"].get<double>(), f["handover_max_sigma"].get<double>());
    } else {
      std::printf("footprints:     no flakes: sigma below %g texels answered by level 0\n",
                  f["pyramid_min_sigma"].get<double>());
    }
    std::printf("                pyramid of %d levels, sigma %g to %g texels; above: %s\n", f["levels"].get<int>(),
                f["pyramid_min_sigma"].get<double>(), f["pyramid_max_sigma"].get<double>(),
                f["unbounded_above_top"].get<bool>() ? "the top level spread to any width"
                                                     : "the top level spread up to 2.5 strides (a clamp)");
  }
  std::printf("\n");
  std::printf("%5s  %-12s  %-24s  %-5s  %12s  %12s  %7s\n", "index", "type", "key", "codec", "stored", "raw", "ratio");
  uint64_t total_stored = 0, total_raw = 0;
  for (size_t i = 0; i < sections.size(); ++i) {
    const format::SectionInfo& s = sections[i];
    const double ratio = s.stored_size ? double(s.raw_size) / double(s.stored_size) : 1.0;
    std::printf("%5zu  %-12s  %-24s  %-5s  %12" PRIu64 "  %12" PRIu64 "  %6.2fx\n", i, typeLabel(s.type).c_str(),
                keyLabel(s.type, s.key).c_str(), format::codecString(format::Codec(s.codec)), s.stored_size, s.raw_size,
                ratio);
    total_stored += s.stored_size;
    total_raw += s.raw_size;
  }
  std::printf("%5s  %-12s  %-24s  %-5s  %12" PRIu64 "  %12" PRIu64 "  %6.2fx\n", "", "total", "", "", total_stored,
              total_raw, total_stored ? double(total_raw) / double(total_stored) : 1.0);
  std::printf("\nmetadata:\n");
  if (reader->find(format::kSectionMetadata) < 0) {
    std::printf("  (none)\n");
  } else if (metadata.is_string()) {
    std::printf("%s\n", metadata_text.c_str());
  } else {
    std::cout << metadata.dump(2) << "\n";
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintinfo
