// SPDX-License-Identifier: Apache-2.0
#include "container_access.h"
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/stdin_input.h>

#include <glintbake/format/json_depth.h>
#include <glintbake/format/validate.h>

#include <cerrno>
#include <cstring>

namespace glintbake::glintinfo {

std::unique_ptr<format::Reader> openContainer(const std::string& argument) {
  const std::string path = cli::resolveInput(argument);
  auto reader = std::make_unique<format::Reader>();
  const format::ContainerStatus status = reader->open(path);
  if (status == format::ContainerStatus::kOk) return reader;
  if (status == format::ContainerStatus::kIoError) {
    const int err = errno;
    throw cli::Error(cli::kExitIo, "cannot read " + path + (err ? std::string(": ") + std::strerror(err) : ""));
  }
  // Let the validator explain: its first error names the exact field.
  format::ValidateOptions options;
  options.check_payloads = false;
  const format::ValidationReport report = format::validateFile(path, options);
  std::string reason = format::statusString(status);
  for (const auto& m : report.messages) {
    if (m.severity == format::Severity::kError) {
      reason = m.message;
      break;
    }
  }
  throw cli::Error(cli::exitCodeOf(status), path + ": " + reason);
}

std::string sectionReadError(format::ContainerStatus status) {
  if (status == format::ContainerStatus::kTooLarge) return "zstd frame window exceeds the reader limit of 128 MiB";
  return format::statusString(status);
}

std::vector<uint8_t> readSectionOrThrow(const format::Reader& reader, const std::string& path, size_t i) {
  std::vector<uint8_t> bytes;
  const format::ContainerStatus status = reader.readSection(i, &bytes);
  if (status != format::ContainerStatus::kOk) {
    throw cli::Error(cli::exitCodeOf(status),
                     path + ": section " + std::to_string(i) + ": " + sectionReadError(status));
  }
  return bytes;
}

std::string readMetadataOrThrow(const format::Reader& reader, const std::string& path) {
  std::string text;
  const format::ContainerStatus status = reader.readMetadata(&text);
  if (status == format::ContainerStatus::kNotFound) return std::string();
  if (status == format::ContainerStatus::kTooLarge) {
    const auto& s = reader.sections()[size_t(reader.find(format::kSectionMetadata))];
    throw cli::Error(cli::kExitInvalidInput, path + ": error-5016: metadata is " + std::to_string(s.raw_size) +
                                                 " bytes, more than the 16 MiB limit");
  }
  if (status != format::ContainerStatus::kOk) {
    throw cli::Error(cli::exitCodeOf(status), path + ": metadata section: " + format::statusString(status));
  }
  return text;
}

cli::Json parseMetadata(const std::string& text) {
  if (text.empty() || format::jsonNestingDepth(text) > size_t(format::kMaxJsonDepth)) return nullptr;
  cli::Json doc = cli::Json::parse(text, nullptr, /*allow_exceptions=*/false);
  return doc.is_discarded() ? cli::Json(nullptr) : doc;
}

std::string typeLabel(uint32_t type) {
  const char* name = format::sectionTypeString(type);
  if (std::strcmp(name, "unknown") == 0 || std::strcmp(name, "private") == 0) return std::to_string(type);
  return name;
}

std::string keyLabel(uint32_t type, uint64_t key) {
  if (type == format::kSectionNdfChunk) {
    return "level " + std::to_string(key >> 32) + ", region " + std::to_string(key & 0xFFFFFFFFu);
  }
  return std::to_string(key);
}

}  // namespace glintbake::glintinfo
