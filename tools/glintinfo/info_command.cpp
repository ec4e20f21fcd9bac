// glintinfo info: header, section table and metadata of a container.
#include "commands.h"
#include "container_access.h"

#include <cinttypes>
#include <cstdio>
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

  // The metadata is shown parsed when it is JSON, as text otherwise (validate reports why).
  cli::Json metadata = nullptr;
  std::string metadata_text;
  const int meta_index = reader->find(format::kSectionMetadata);
  if (meta_index >= 0) {
    const auto bytes = readSectionOrThrow(*reader, options.file, size_t(meta_index));
    metadata_text.assign(bytes.begin(), bytes.end());
    metadata = cli::Json::parse(metadata_text, nullptr, /*allow_exceptions=*/false);
    if (metadata.is_discarded()) metadata = metadata_text;
  }

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
    tool.printJson(doc);
    return cli::kExitOk;
  }

  std::printf("file:           %s\n", options.file.c_str());
  std::printf("format:         %u.%u\n", header.version_major, header.version_minor);
  std::printf("asset kind:     %s\n", kindLabel(header.asset_kind).c_str());
  std::printf("file size:      %" PRIu64 " bytes\n", header.file_size);
  std::printf("file checksum:  %s (XXH3-64)\n", hex64(header.file_checksum).c_str());
  std::printf("sections:       %u\n\n", header.section_count);
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
  if (meta_index < 0) {
    std::printf("  (none)\n");
  } else if (metadata.is_string()) {
    std::printf("%s\n", metadata_text.c_str());
  } else {
    std::cout << metadata.dump(2) << "\n";
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintinfo
