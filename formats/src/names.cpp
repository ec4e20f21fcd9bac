// Stable names of status codes, asset kinds and codecs (used in messages, JSON and metadata), and
// the magic test.
#include "layout.h"

#include <glintbake/format/container.h>
#include <glintbake/format/kinds/flakes.h>

#include <cstring>
#include <string>

namespace glintbake::format {

const char* statusString(Status status) {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kIoError:
      return "i/o error";
    case Status::kBadMagic:
      return "not a glintbake container";
    case Status::kUnsupportedVersion:
      return "unsupported container version";
    case Status::kCorruptHeader:
      return "corrupt header";
    case Status::kCorruptIndex:
      return "corrupt section index";
    case Status::kChecksumMismatch:
      return "checksum mismatch";
    case Status::kDecompressFailed:
      return "section does not decode";
    case Status::kTooLarge:
      return "exceeds a reader limit";
    case Status::kNotFound:
      return "section not found";
    case Status::kInvalidArgument:
      return "invalid argument";
    case Status::kTruncated:
      return "file is truncated";
  }
  return "unknown status";
}

namespace {

struct KindName {
  AssetKind kind;
  const char* name;
};

constexpr KindName kKindNames[] = {
    {AssetKind::kNdfPyramid, "ndf-pyramid"}, {AssetKind::kTensorNdf, "tensor-ndf"},
    {AssetKind::kLtcTable, "ltc-table"},     {AssetKind::kRoughness, "roughness"},
    {AssetKind::kWangTiles, "wang-tiles"},   {AssetKind::kTinyExample, "tiny-example"},
    {AssetKind::kGlitter, "glitter"},        {AssetKind::kTest, "test"},
};

}  // namespace

const char* assetKindString(AssetKind kind) {
  for (const KindName& entry : kKindNames) {
    if (entry.kind == kind) return entry.name;
  }
  return "unknown";
}

bool assetKindFromString(const std::string& name, AssetKind* kind) {
  for (const KindName& entry : kKindNames) {
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

namespace {

struct TypeName {
  uint32_t type;
  const char* name;
};

constexpr TypeName kTypeNames[] = {
    {kSectionMetadata, "metadata"},        {kSectionNdfLevel, "ndf-level"},     {kSectionNdfChunk, "ndf-chunk"},
    {kSectionTensorIndex, "tensor-index"}, {kSectionTensorInfo, "tensor-info"}, {kSectionTensorGroup, "tensor-group"},
    {kSectionLtcTable, "ltc-table"},       {kSectionRoughness, "roughness"},    {kSectionFlakes, "flakes"},
    {kSectionImage, "image"},
};

}  // namespace

const char* sectionTypeString(uint32_t type) {
  for (const TypeName& entry : kTypeNames) {
    if (entry.type == type) return entry.name;
  }
  return type >= kSectionFirstPrivate ? "private" : "unknown";
}

bool sectionTypeFromString(const std::string& name, uint32_t* type) {
  for (const TypeName& entry : kTypeNames) {
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
