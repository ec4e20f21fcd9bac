// SPDX-License-Identifier: Apache-2.0
// Full validation of a container: every structural rule of formats/SPEC.md, every section's
// checksum and decoding, image-section headers, the whole-file checksum and the metadata section.
// The same function serves `glintinfo validate` and the fuzzer (tests/fuzz/fuzz_container.cpp).
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::format {

enum class Severity : int32_t {
  kWarning = 1,  // the file is usable; something is unusual (newer minor, unknown codec, ...)
  kError = 2,    // the file violates the specification
};
const char* severityString(Severity severity);  // "warning" or "error"

// One finding. Ids are stable across versions and grouped by family (SPEC.md, "Validation"):
// 1xxx I/O, 2xxx header, 3xxx index, 4xxx section payloads, 5xxx metadata, 6xxx kind-specific.
struct ValidationMessage {
  int id = 0;
  Severity severity = Severity::kError;
  std::string message;  // one line, no trailing period
};

struct ValidationReport {
  std::vector<ValidationMessage> messages;  // in the order the checks ran
  // The first failing container status: kIoError (the file could not be read), kUnsupportedVersion
  // (newer major), any other value (the container is corrupt). kOk when structure, checksums and
  // decoding are sound; metadata and kind-specific errors make the report invalid without a status.
  ContainerStatus status = ContainerStatus::kOk;
  bool valid() const { return errorCount() == 0; }
  size_t errorCount() const;
  size_t warningCount() const;
};

struct ValidateOptions {
  uint64_t max_raw_section_size = kDefaultMaxRawSectionSize;  // as ReaderOptions
  bool check_payloads = true;  // read and decode every section (4xxx); off: header/index/metadata
};

// Validates a container held in memory. Safe on untrusted input: never reads outside
// [data, data + size), never allocates more than max_raw_section_size per section at a time, never
// crashes; every problem becomes a message. Thread-safe (no shared state).
ValidationReport validate(const void* data, size_t size, const ValidateOptions& options = {});

// Same, reading the file with positioned reads. Sections are read and checked as they decode, in
// 1 MiB pieces: memory is bounded by the metadata (16 MiB) and zstd's window (at most
// kMaxZstdWindowSize; frames of larger windows are refused, error-4010), not by the sections'
// stored or decoded sizes. A file that cannot be opened yields error-1001 and status kIoError.
ValidationReport validateFile(const std::string& path, const ValidateOptions& options = {});

// Checks a metadata JSON text against schemas/container-metadata.schema.json (written out as hand
// checks) and that its asset_kind names `kind`. Appends 5xxx messages. Exposed for tools that
// want to check metadata before writing it.
void validateMetadata(const std::string& json_utf8, AssetKind kind, std::vector<ValidationMessage>* messages);

// Parses the ImageSectionHeader at the start of a section's raw bytes; false if the bytes are too
// short, the magic differs, or width*height*channels*layers*4 + 32 != size. Safe on untrusted input.
bool parseImageSection(const uint8_t* data, size_t size, ImageSectionHeader* header);
// Same verdict from the section's first bytes alone (`head`, head_size >= 32 of them, else false)
// and its raw size: for callers that stream the section instead of holding it.
bool parseImageSectionHead(const uint8_t* head, size_t head_size, uint64_t section_size, ImageSectionHeader* header);

}  // namespace glintbake::format
