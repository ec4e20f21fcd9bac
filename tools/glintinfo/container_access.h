// SPDX-License-Identifier: Apache-2.0
// Opening containers for glintinfo: status-to-exit-code mapping and one-line error messages that
// name the file and the first problem the validator finds.
#pragma once

#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace glintbake::glintinfo {

// io -> 2; bad magic, corrupt, checksum, truncated, too large -> 3; newer major -> 5.

// Opens path; throws cli::Error with the mapped exit code and a message such as
// "a.gbk: header checksum mismatch (stored ..., computed ...)".
std::unique_ptr<format::Reader> openContainer(const std::string& path);

// Why section i cannot be read, for messages: the status's name, or for kTooLarge (which reading a
// section of an open reader only returns for the zstd window) the limit.
std::string sectionReadError(format::ContainerStatus status);

// Reads section i; throws cli::Error (exit 3 for damaged data) naming the file and section.
std::vector<uint8_t> readSectionOrThrow(const format::Reader& reader, const std::string& path, size_t i);

// The metadata text (empty when the file has none); throws cli::Error (exit 3) when it is larger
// than format::kMaxMetadataSize (refused before it is decoded) or cannot be read.
std::string readMetadataOrThrow(const format::Reader& reader, const std::string& path);

// The metadata parsed, when it is JSON nested at most format::kMaxJsonDepth levels; otherwise
// nullptr (see validate for the reason). Linear in the text's size.
cli::Json parseMetadata(const std::string& text);

// "ndf-chunk" or the decimal type number when it has no registered name.
std::string typeLabel(uint32_t type);

// Human form of a key: "level 1, region 3" for NDF chunks, the number otherwise.
std::string keyLabel(uint32_t type, uint64_t key);

}  // namespace glintbake::glintinfo
