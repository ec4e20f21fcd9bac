// SPDX-License-Identifier: Apache-2.0
// Stable names of status codes, asset kinds, section types and codecs (used in messages, JSON and
// metadata; kind and type names come from the registry, kinds.h), and the magic test.
#include "layout.h"

#include <glintbake/format/container.h>
#include <glintbake/format/kinds.h>

#include <cstring>
#include <string>

namespace glintbake::format {

const char* statusString(ContainerStatus status) {
  switch (status) {
    case ContainerStatus::kOk:
      return "ok";
    case ContainerStatus::kIoError:
      return "i/o error";
    case ContainerStatus::kBadMagic:
      return "not a glintbake container";
    case ContainerStatus::kUnsupportedVersion:
      return "unsupported container version";
    case ContainerStatus::kCorruptHeader:
      return "corrupt header";
    case ContainerStatus::kCorruptIndex:
      return "corrupt section index";
    case ContainerStatus::kChecksumMismatch:
      return "checksum mismatch";
    case ContainerStatus::kDecompressFailed:
      return "section does not decode";
    case ContainerStatus::kTooLarge:
      return "exceeds a reader limit";
    case ContainerStatus::kNotFound:
      return "section not found";
    case ContainerStatus::kInvalidArgument:
      return "invalid argument";
    case ContainerStatus::kTruncated:
      return "file is truncated";
  }
  return "unknown status";
}

const char* assetKindString(AssetKind kind) {
  const KindInfo* entry = findKind(kind);
  return entry ? entry->name : "unknown";
}

bool assetKindFromString(const std::string& name, AssetKind* kind) {
  for (const KindInfo& entry : kKindRegistry) {
    if (name == entry.name) {
      if (kind) *kind = entry.kind;
      return true;
    }
  }
  return false;
}

const char* codecString(Codec codec) {
  switch (codec) {
    case Codec::kRaw:
      return "raw";
    case Codec::kZstd:
      return "zstd";
  }
  return "unknown";
}

const char* sectionTypeString(uint32_t type) {
  for (const SectionTypeInfo& entry : kSectionTypeRegistry) {
    if (entry.type == type) return entry.name;
  }
  return type >= kSectionFirstPrivate ? "private" : "unknown";
}

bool sectionTypeFromString(const std::string& name, uint32_t* type) {
  for (const SectionTypeInfo& entry : kSectionTypeRegistry) {
    if (name == entry.name) {
      if (type) *type = entry.type;
      return true;
    }
  }
  // A number: decimal, or hexadecimal with a 0x prefix; at most 32 bits.
  const bool hex = name.size() > 2 && name[0] == '0' && (name[1] == 'x' || name[1] == 'X');
  const size_t start = hex ? 2 : 0;
  if (name.size() <= start) return false;
  uint64_t value = 0;
  for (size_t i = start; i < name.size(); ++i) {
    const char c = name[i];
    int digit;
    if (c >= '0' && c <= '9')
      digit = c - '0';
    else if (hex && c >= 'a' && c <= 'f')
      digit = c - 'a' + 10;
    else if (hex && c >= 'A' && c <= 'F')
      digit = c - 'A' + 10;
    else
      return false;
    value = value * (hex ? 16 : 10) + uint64_t(digit);
    if (value > UINT32_MAX) return false;
  }
  if (type) *type = uint32_t(value);
  return true;
}

bool hasContainerMagic(const void* data, size_t size) {
  return data != nullptr && size >= sizeof(layout::kMagic) &&
         std::memcmp(data, layout::kMagic, sizeof(layout::kMagic)) == 0;
}

}  // namespace glintbake::format
