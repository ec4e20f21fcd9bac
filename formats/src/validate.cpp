// SPDX-License-Identifier: Apache-2.0
// validate(): runs every check of formats/SPEC.md ("Validation") and reports each finding with
// its stable id. Structural checks are shared with Reader::open() (container_parse.cpp).
#include <glintbake/format/json_depth.h>
#include <glintbake/format/kinds.h>
#include <glintbake/format/kinds/flakes.h>
#include <glintbake/format/kinds/glitter.h>
#include <glintbake/format/kinds/tiny_example.h>
#include <glintbake/format/kinds/wang.h>
#include <glintbake/format/validate.h>

#include "byte_source.h"
#include "container_parse.h"
#include "layout.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace glintbake::format {
namespace {

constexpr size_t kMaxMetadataBytes = size_t(kMaxMetadataSize);
constexpr int kMaxMetadataDepth = kMaxJsonDepth;
constexpr const char* kMetadataSchemaId = "glintbake.container-metadata/1";

// parseImageSection from the first 32 bytes of a section of `size` bytes (defined below).
bool parseImageHeader(const uint8_t* data, uint64_t size, ImageSectionHeader* header);

class Collector final : public detail::Diagnostics {
 public:
  explicit Collector(std::vector<ValidationMessage>* messages) : messages_(messages) {}
  void error(int id, const std::string& message) override { messages_->push_back({id, Severity::kError, message}); }
  void warning(int id, const std::string& message) override { messages_->push_back({id, Severity::kWarning, message}); }

 private:
  std::vector<ValidationMessage>* messages_;
};

void addError(std::vector<ValidationMessage>* messages, int id, std::string message) {
  messages->push_back({id, Severity::kError, std::move(message)});
}
void addWarning(std::vector<ValidationMessage>* messages, int id, std::string message) {
  messages->push_back({id, Severity::kWarning, std::move(message)});
}

// The range of section types owned by an asset kind that a tool writes (kinds.h): such an asset
// must hold at least one of them.
bool kindTypeRange(AssetKind kind, uint32_t* first, uint32_t* last) {
  const KindInfo* info = findKind(kind);
  if (!info || info->tool[0] == '\0' || info->last_type == 0) return false;
  *first = info->first_type;
  *last = info->last_type;
  return true;
}

std::string describe(size_t index, const SectionInfo& s) {
  return "section " + std::to_string(index) + " (type " + std::to_string(s.type) + ", key " + std::to_string(s.key) +
         ")";
}

// What the payload checks need of a section, gathered while it streams past (detail::streamSection)
// so that no section is ever held whole unless it is a small record: its size, its first bytes (the
// image header or a record), every byte of the sections checked as a whole (metadata, at most
// 16 MiB, records whose size is already known to be right, and a glitter integral table of at
// most 16 MiB), and tallies of its 32-bit floats.
struct Payload {
  static constexpr size_t kHead = 256;  // >= every record and the image header
  uint64_t size = 0;
  std::vector<uint8_t> head;                   // the first min(size, kHead) bytes
  std::vector<uint8_t> whole;                  // every byte, when keep_whole
  uint8_t tail[8] = {};                        // the last min(size, 8) bytes, at the end
  uint64_t nonfinite_after_image_header = 0;   // floats at offsets >= 32
  bool nonfinite_after_flakes_record = false;  // floats at offsets >= sizeof(FlakesRecord)
  bool outside_unit = false;                   // !(|v| <= 1) for a float at any offset
  bool negative_after_image_header = false;    // v < 0 for a float at offsets >= 32
  bool above_one_after_image_header = false;   // v > 1 for a float at offsets >= 32
};
static_assert(sizeof(FlakesRecord) <= Payload::kHead && sizeof(WangRecord) <= Payload::kHead &&
                  sizeof(TinyExampleRecord) <= Payload::kHead && layout::kImageHeaderSize <= Payload::kHead,
              "records fit the head");
static_assert(sizeof(FlakesRecord) % 4 == 0 && layout::kImageHeaderSize % 4 == 0, "floats on one grid");

class PayloadSink final : public detail::SectionSink {
 public:
  PayloadSink(Payload* payload, bool keep_whole) : p_(payload), keep_whole_(keep_whole) {}
  void consume(const uint8_t* data, size_t size) override {
    const size_t head = std::min(size, Payload::kHead - std::min(Payload::kHead, p_->head.size()));
    p_->head.insert(p_->head.end(), data, data + head);
    if (keep_whole_) p_->whole.insert(p_->whole.end(), data, data + size);
    size_t i = 0;
    while (carried_ != 0 && i < size) {  // a float split between two pieces
      carry_[carried_++] = data[i++];
      if (carried_ == 4) {
        carried_ = 0;
        noteAt(carry_);
      }
    }
    for (; i + 4 <= size; i += 4) noteAt(data + i);
    while (i < size) carry_[carried_++] = data[i++];
    p_->size += size;
    const size_t keep = std::min<size_t>(size, sizeof(p_->tail));  // the last bytes so far
    std::memmove(p_->tail, p_->tail + keep, sizeof(p_->tail) - keep);
    std::memcpy(p_->tail + sizeof(p_->tail) - keep, data + size - keep, keep);
  }

 private:
  void noteAt(const uint8_t* bytes) {
    float v;
    std::memcpy(&v, bytes, 4);
    note(v, offset_);
    offset_ += 4;
  }
  void note(float v, uint64_t offset) {
    const bool finite = std::isfinite(v);
    if (!(std::fabs(v) <= 1.0f)) p_->outside_unit = true;
    if (offset >= sizeof(FlakesRecord) && !finite) p_->nonfinite_after_flakes_record = true;
    if (offset >= layout::kImageHeaderSize) {
      if (!finite) ++p_->nonfinite_after_image_header;
      if (v < 0.0f) p_->negative_after_image_header = true;
      if (v > 1.0f) p_->above_one_after_image_header = true;
    }
  }
  Payload* p_;
  bool keep_whole_;
  uint8_t carry_[4] = {};
  size_t carried_ = 0;
  uint64_t offset_ = 0;
};

// The flakes section (SPEC.md 10.5): its record passes checkFlakesRecord, its normals are finite and
// a version-3 trailer passes checkFlakesTrailer.
void checkFlakesPayload(size_t index, const SectionInfo& s, const Payload& raw,
                        std::vector<ValidationMessage>* messages) {
  FlakesRecord rec;
  if (raw.size < sizeof(rec)) {
    addError(messages, 4008, describe(index, s) + ": shorter than the flakes record");
    return;
  }
  std::memcpy(&rec, raw.head.data(), sizeof(rec));
  if (const char* why = checkFlakesRecord(rec, size_t(raw.size))) {
    addError(messages, 4008, describe(index, s) + ": " + why);
    return;
  }
  if (raw.nonfinite_after_flakes_record) addError(messages, 4008, describe(index, s) + ": non-finite normals");
  if (rec.version >= 3) {
    FlakesTrailer trailer;
    std::memcpy(&trailer, raw.tail, sizeof(trailer));
    if (const char* why = checkFlakesTrailer(trailer)) addError(messages, 4008, describe(index, s) + ": " + why);
  }
}

// The wang-tiles sections (SPEC.md 10.7): the record passes checkWangRecord; the edges section
// passes checkWangEdges against the record and the texels section has the record's size and
// finite values within [-1, 1] (both need the record, which writers put first). The embedded tile
// assets are left to the runtime's loader (6004).
void checkWangPayload(size_t index, const SectionInfo& s, const Payload& raw, WangRecord* record, bool* have_record,
                      std::vector<ValidationMessage>* messages) {
  if (s.type == kSectionWangInfo) {
    if (raw.size != sizeof(WangRecord)) {
      addError(messages, 4009, describe(index, s) + ": not the size of the wang record");
      return;
    }
    std::memcpy(record, raw.head.data(), sizeof(WangRecord));
    if (const char* why = checkWangRecord(*record)) {
      addError(messages, 4009, describe(index, s) + ": " + why);
      return;
    }
    *have_record = true;
    return;
  }
  if (!*have_record) return;
  if (s.type == kSectionWangEdges) {
    // Kept whole only when of the record's size; otherwise checkWangEdges reports the size alone.
    static const uint8_t kNone = 0;
    const void* bytes = raw.whole.size() == raw.size && !raw.whole.empty() ? raw.whole.data() : &kNone;
    if (const char* why = checkWangEdges(*record, bytes, size_t(raw.size)))
      addError(messages, 4009, describe(index, s) + ": " + why);
  } else if (s.type == kSectionWangTexels) {
    if (raw.size != wangTexelsBytes(*record)) {
      addError(messages, 4009, describe(index, s) + ": size does not match the wang record");
      return;
    }
    if (raw.outside_unit) addError(messages, 4009, describe(index, s) + ": texel values not finite or outside [-1, 1]");
  }
}

void checkImagePayload(size_t index, const SectionInfo& s, const Payload& raw,
                       std::vector<ValidationMessage>* messages) {
  const bool has_magic = raw.size >= 4 && layout::load32(raw.head.data()) == layout::kImageMagic;
  if (!has_magic) {
    // Only the generic image section must carry an image header; others may hold anything.
    if (s.type == kSectionImage) addError(messages, 4004, describe(index, s) + ": missing the GIMG image header");
    return;
  }
  ImageSectionHeader header;
  if (!parseImageHeader(raw.head.data(), raw.size, &header)) {
    addError(messages, 4005,
             describe(index, s) + ": image header dimensions do not match the section's " + std::to_string(raw.size) +
                 " bytes");
    return;
  }
  if (header.flags != 0 || header.reserved != 0) {
    addWarning(messages, 4007, describe(index, s) + ": reserved image header fields are not zero");
  }
  if (raw.nonfinite_after_image_header != 0) {
    addError(messages, 4006,
             describe(index, s) + ": " + std::to_string(raw.nonfinite_after_image_header) + " non-finite values");
  }
}

// A kind's fixed-size record: exactly sizeof(Record) bytes passing its check (null when valid);
// otherwise error `id` naming the problem. True when the record is usable.
template <typename Record>
bool readCheckedRecord(size_t index, const SectionInfo& s, const Payload& raw, int id, const char* what,
                       const char* (*check)(const Record&), Record* record, std::vector<ValidationMessage>* messages) {
  static_assert(sizeof(Record) <= Payload::kHead, "records fit the head");
  if (raw.size != sizeof(Record)) {
    addError(messages, id,
             describe(index, s) + ": the " + what + " record is not " + std::to_string(sizeof(Record)) + " bytes");
    return false;
  }
  std::memcpy(record, raw.head.data(), sizeof(Record));
  if (const char* why = check(*record)) {
    addError(messages, id, describe(index, s) + ": " + why);
    return false;
  }
  return true;
}

// What the payload pass saw of a tiny-example asset's own sections (SPEC.md 10.8).
struct TinyExampleSeen {
  int info = 0;  // info sections read
  bool record_ok = false;
  TinyExampleRecord record;
  std::vector<std::pair<uint64_t, ImageSectionHeader>> levels;  // (key, image header) of readable levels
  int layouts = 0;                                              // layout sections (type 115)
};

void noteTinyExamplePayload(size_t index, const SectionInfo& s, const Payload& raw, TinyExampleSeen* seen,
                            std::vector<ValidationMessage>* messages) {
  if (s.type == kSectionTinyExampleInfo) {
    ++seen->info;
    seen->record_ok =
        readCheckedRecord(index, s, raw, 6006, "tiny-example", checkTinyExampleRecord, &seen->record, messages);
  } else if (s.type == kSectionTinyExampleTexels) {
    if (raw.outside_unit)
      addError(messages, 6006, describe(index, s) + ": example texels not finite or outside [-1, 1]");
  } else if (s.type == kSectionTinyExampleLevel) {
    ImageSectionHeader header;
    if (!parseImageHeader(raw.head.data(), raw.size, &header)) return;  // 4004/4005 already reported
    if (raw.negative_after_image_header) {
      addError(messages, 6006, describe(index, s) + ": negative NDF values");
      return;
    }
    seen->levels.emplace_back(s.key, header);
  } else if (s.type == kSectionTinyExampleLevelHalf) {
    // binary16 values: the header's dimensions against the size; values are checked by readers.
    if (raw.size < layout::kImageHeaderSize || layout::load32(raw.head.data()) != kTinyHalfImageMagic) {
      addError(messages, 6006, describe(index, s) + ": missing the GIMH header of binary16 tile images");
      return;
    }
    ImageSectionHeader h;
    h.width = layout::load32(raw.head.data() + 4);
    h.height = layout::load32(raw.head.data() + 8);
    h.channels = layout::load32(raw.head.data() + 12);
    h.layers = layout::load32(raw.head.data() + 16);
    if (uint64_t(h.width) * h.height * h.channels * h.layers * 2 + layout::kImageHeaderSize != raw.size) {
      addError(messages, 6006, describe(index, s) + ": binary16 header dimensions do not match the section's size");
      return;
    }
    seen->levels.emplace_back(s.key, h);
  } else if (s.type == kSectionTinyExampleLayout) {
    ++seen->layouts;
    ImageSectionHeader h;
    if (!parseImageHeader(raw.head.data(), raw.size, &h)) {
      addError(messages, 6006, describe(index, s) + ": the layout is not an image section of its size");
      return;
    }
    if (s.key != 0 || h.layers != 1 || h.width < 1 || h.height < 1 || h.width > kMaxTinyLayoutSide ||
        h.height > kMaxTinyLayoutSide || h.channels < 1 || h.channels > kMaxTinyLayoutChannels)
      addError(messages, 6006,
               describe(index, s) + ": the layout is not one image of 1..1024 x 1..1024 cells, 1..3 channels, key 0");
    else if (raw.nonfinite_after_image_header != 0 || raw.negative_after_image_header ||
             raw.above_one_after_image_header)
      addError(messages, 6006, describe(index, s) + ": layout values not finite or outside [0, 1]");
  }
}

// The layout of a tiny-example asset: one valid record, the example's texels, and every level's
// tile images with the record's sizes.
void checkTinyExampleLayout(const std::vector<SectionInfo>& sections, const TinyExampleSeen& seen,
                            std::vector<ValidationMessage>* messages) {
  if (seen.info != 1) {
    addError(messages, 6006,
             "a tiny-example asset holds " + std::to_string(seen.info) + " info sections (type 112), not one");
    return;
  }
  if (!seen.record_ok) return;
  const TinyExampleRecord& r = seen.record;
  const uint64_t n = r.example_size;
  auto texels = std::find_if(sections.begin(), sections.end(),
                             [](const SectionInfo& s) { return s.type == kSectionTinyExampleTexels && s.key == 0; });
  if (texels == sections.end() || texels->raw_size != n * n * 8)
    addError(messages, 6006, "the tiny-example texels (type 113) are missing or not example_size^2 (n_x, n_y) pairs");
  const bool half = (r.flags & kTinyFlagHalf) != 0;
  const uint32_t level_type = half ? kSectionTinyExampleLevelHalf : kSectionTinyExampleLevel;
  for (uint32_t l = 0; l < r.levels; ++l) {
    auto level = std::find_if(sections.begin(), sections.end(),
                              [&](const SectionInfo& s) { return s.type == level_type && s.key == l; });
    if (level == sections.end() || level->raw_size != tinyLevelSectionSize(r, l)) {
      addError(messages, 6006,
               "tiny-example level " + std::to_string(l) + " (type " + std::to_string(level_type) +
                   ") is missing or has the wrong size");
      continue;
    }
    const uint64_t m = tinyTilesPerSide(r.example_size, l);
    for (const auto& [key, h] : seen.levels) {
      if (key == l && (h.width != r.ndf_res || h.height != r.ndf_res || h.channels != 1 || h.layers != m * m))
        addError(messages, 6006, "tiny-example level " + std::to_string(l) + " images are not tiles^2 layers of R x R");
    }
  }
  const bool has_layout = (r.flags & kTinyFlagLayout) != 0;
  if (has_layout && seen.layouts != 1)
    addError(messages, 6006,
             "the record asks for a layout image, and the asset holds " + std::to_string(seen.layouts) +
                 " layout sections (type 115), not one");
  if (!has_layout && seen.layouts != 0)
    addError(messages, 6006, "a layout section (type 115) in an asset whose record has no layout");
  for (const SectionInfo& s : sections) {
    if ((s.type == kSectionTinyExampleLevel || s.type == kSectionTinyExampleLevelHalf) && s.key >= r.levels)
      addError(messages, 6006, "tiny-example level " + std::to_string(s.key) + " beyond the record's levels");
    if (s.type == (half ? kSectionTinyExampleLevel : kSectionTinyExampleLevelHalf))
      addError(messages, 6006,
               std::string("a ") + (half ? "float32" : "binary16") + " level section (type " + std::to_string(s.type) +
                   ") in an asset whose record stores its levels as " + (half ? "binary16" : "float32"));
  }
}

// What the payload pass saw of a glitter asset's own sections (SPEC.md 10.6).
struct GlitterSeen {
  int info = 0;  // info sections read
  bool record_ok = false;
  GlitterRecord record;
  int tables = 0;              // integral sections read
  int64_t table_entries = -1;  // entries of a table that passed its checks
};

// The glitter record passes checkGlitterRecord and the integral table checkGlitterIntegrals, the
// same checks the runtime's loader makes (one implementation, formats/kinds/glitter.h).
void noteGlitterPayload(size_t index, const SectionInfo& s, const Payload& raw, GlitterSeen* seen,
                        std::vector<ValidationMessage>* messages) {
  if ((s.type == kSectionGlitterInfo || s.type == kSectionGlitterIntegrals) && s.key != 0) {
    addError(messages, 6007, describe(index, s) + ": glitter sections have key 0");
    return;
  }
  if (s.type == kSectionGlitterInfo) {
    ++seen->info;
    seen->record_ok = readCheckedRecord(index, s, raw, 6007, "glitter", checkGlitterRecord, &seen->record, messages);
  } else if (s.type == kSectionGlitterIntegrals) {
    ++seen->tables;
    if (raw.size % sizeof(GlitterIntegral) != 0) {
      addError(messages, 6007, describe(index, s) + ": not a whole number of 16-byte integral entries");
      return;
    }
    if (raw.size > uint64_t(kMaxGlitterIntegrals) * sizeof(GlitterIntegral) || raw.whole.size() != raw.size) {
      addError(messages, 6007, describe(index, s) + ": more than 2^20 integral entries");
      return;
    }
    const size_t count = size_t(raw.size) / sizeof(GlitterIntegral);
    std::vector<GlitterIntegral> table(count);
    if (count > 0) std::memcpy(table.data(), raw.whole.data(), size_t(raw.size));
    if (const char* why = checkGlitterIntegrals(table.data(), count)) {
      addError(messages, 6007, describe(index, s) + ": " + why);
      return;
    }
    seen->table_entries = int64_t(count);
  }
}

// The layout of a glitter asset: one valid record and one integral table of its integral_count.
void checkGlitterSections(const GlitterSeen& seen, std::vector<ValidationMessage>* messages) {
  if (const char* why = checkGlitterLayout(size_t(seen.info), size_t(seen.tables))) {
    addError(messages, 6007,
             std::string(why) + "; this one holds " + std::to_string(seen.info) + " glitter-info and " +
                 std::to_string(seen.tables) + " glitter-integrals sections");
    return;
  }
  if (seen.record_ok && seen.table_entries >= 0 && uint64_t(seen.table_entries) != seen.record.integral_count)
    addError(messages, 6007,
             "the glitter integral table holds " + std::to_string(seen.table_entries) + " entries, the record says " +
                 std::to_string(seen.record.integral_count));
}

bool looksLikeAbsolutePath(const std::string& s) {
  if (s.size() >= 2 && s[0] == '/' && s[1] != ' ') return true;    // POSIX
  if (s.size() >= 2 && s[0] == '\\' && s[1] == '\\') return true;  // UNC
  if (s.size() >= 3 && std::isalpha(static_cast<unsigned char>(s[0])) && s[1] == ':' && (s[2] == '\\' || s[2] == '/'))
    return true;                                                 // drive letter
  if (s.size() >= 2 && s[0] == '~' && s[1] == '/') return true;  // home-relative
  return false;
}

bool isHashString(const std::string& s) {
  static const std::string kPrefix = "xxh3-128:";
  if (s.size() != kPrefix.size() + 32 || s.compare(0, kPrefix.size(), kPrefix) != 0) return false;
  return std::all_of(s.begin() + std::ptrdiff_t(kPrefix.size()), s.end(),
                     [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

}  // namespace

const char* severityString(Severity severity) { return severity == Severity::kWarning ? "warning" : "error"; }

size_t ValidationReport::errorCount() const {
  return size_t(std::count_if(messages.begin(), messages.end(),
                              [](const ValidationMessage& m) { return m.severity == Severity::kError; }));
}

size_t ValidationReport::warningCount() const { return messages.size() - errorCount(); }

bool parseImageSection(const uint8_t* data, size_t size, ImageSectionHeader* header) {
  return data != nullptr && parseImageHeader(data, size, header);
}

bool parseImageSectionHead(const uint8_t* head, size_t head_size, uint64_t section_size, ImageSectionHeader* header) {
  return head != nullptr && head_size >= layout::kImageHeaderSize && parseImageHeader(head, section_size, header);
}

namespace {

bool parseImageHeader(const uint8_t* data, uint64_t size, ImageSectionHeader* header) {
  if (size < layout::kImageHeaderSize) return false;
  ImageSectionHeader h;
  h.magic = layout::load32(data);
  h.width = layout::load32(data + 4);
  h.height = layout::load32(data + 8);
  h.channels = layout::load32(data + 12);
  h.layers = layout::load32(data + 16);
  h.flags = layout::load32(data + 20);
  h.reserved = layout::load64(data + 24);
  if (h.magic != layout::kImageMagic) return false;
  if (h.width == 0 || h.height == 0 || h.channels == 0 || h.layers == 0) return false;
  // Four 32-bit factors: the product of the first two fits in 64 bits; divide instead of
  // multiplying further so no product can overflow.
  const uint64_t payload = size - layout::kImageHeaderSize;
  if (payload % 4 != 0) return false;
  uint64_t values = payload / 4;
  const uint64_t factors[4] = {h.width, h.height, h.channels, h.layers};
  for (uint64_t f : factors) {
    if (values % f != 0) return false;
    values /= f;
  }
  if (values != 1) return false;
  if (header) *header = h;
  return true;
}

}  // namespace

void validateMetadata(const std::string& text, AssetKind kind, std::vector<ValidationMessage>* messages) {
  if (text.size() > kMaxMetadataBytes) {
    addError(messages, 5016, "metadata is " + std::to_string(text.size()) + " bytes, more than the 16 MiB limit");
    return;
  }
  if (jsonNestingDepth(text) > size_t(kMaxMetadataDepth)) {
    addError(messages, 5003, "metadata JSON is nested deeper than " + std::to_string(kMaxMetadataDepth) + " levels");
    return;
  }
  const nlohmann::json doc = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) {
    addError(messages, 5003, "metadata is not valid UTF-8 JSON");
    return;
  }
  if (!doc.is_object()) {
    addError(messages, 5004, "metadata is not a JSON object");
    return;
  }

  auto schema = doc.find("schema");
  if (schema == doc.end() || !schema->is_string() || schema->get<std::string>() != kMetadataSchemaId) {
    addError(messages, 5005, std::string("metadata \"schema\" must be \"") + kMetadataSchemaId + "\"");
  }
  auto asset_kind = doc.find("asset_kind");
  if (asset_kind == doc.end() || !asset_kind->is_string()) {
    addError(messages, 5006, "metadata \"asset_kind\" is missing or not a string");
  } else if (findKind(kind) != nullptr && asset_kind->get<std::string>() != assetKindString(kind)) {
    addError(messages, 5007,
             "metadata asset_kind \"" + asset_kind->get<std::string>() + "\" does not match the header's \"" +
                 assetKindString(kind) + "\"");
  }
  auto generator = doc.find("generator");
  if (generator == doc.end() || !generator->is_object() || !generator->contains("tool") ||
      !(*generator)["tool"].is_string() || !generator->contains("version") || !(*generator)["version"].is_string()) {
    addError(messages, 5008, "metadata \"generator\" must be an object with string \"tool\" and \"version\"");
  }
  auto parameters = doc.find("parameters");
  if (parameters == doc.end() || !parameters->is_object()) {
    addError(messages, 5009, "metadata \"parameters\" is missing or not an object");
  }
  auto inputs = doc.find("inputs");
  if (inputs == doc.end() || !inputs->is_array()) {
    addError(messages, 5010, "metadata \"inputs\" is missing or not an array");
  } else {
    for (size_t i = 0; i < inputs->size(); ++i) {
      const auto& input = (*inputs)[i];
      const std::string where = "metadata inputs[" + std::to_string(i) + "]";
      if (!input.is_object() || !input.contains("name") || !input["name"].is_string() || !input.contains("hash") ||
          !input["hash"].is_string() || input.size() != 2) {
        addError(messages, 5010, where + " must be an object with exactly string \"name\" and \"hash\"");
        continue;
      }
      const std::string name = input["name"].get<std::string>();
      if (name.empty() || name.find_first_of("/\\") != std::string::npos) {
        addError(messages, 5011, where + ".name \"" + name + "\" must be a file name without '/' or '\\'");
      }
      if (!isHashString(input["hash"].get<std::string>())) {
        addError(messages, 5012, where + ".hash must match xxh3-128:<32 lowercase hex digits>");
      }
    }
  }
  auto asset = doc.find("asset");
  if (asset != doc.end() && !asset->is_object()) addError(messages, 5013, "metadata \"asset\" is not an object");
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    static const char* kKnown[] = {"schema", "asset_kind", "generator", "parameters", "inputs", "asset"};
    if (std::none_of(std::begin(kKnown), std::end(kKnown), [&](const char* k) { return it.key() == k; })) {
      addWarning(messages, 5015, "metadata has an unknown property \"" + it.key() + "\"");
    }
  }

  // Provenance must never leak a private path: look at every string, iteratively (depth is bounded
  // above, but an explicit stack keeps the walk independent of it).
  std::vector<std::pair<const nlohmann::json*, std::string>> stack{{&doc, ""}};
  while (!stack.empty()) {
    auto [node, where] = stack.back();
    stack.pop_back();
    if (node->is_string()) {
      if (looksLikeAbsolutePath(node->get_ref<const std::string&>())) {
        addError(messages, 5014,
                 "metadata " + (where.empty() ? std::string("value") : where) + " holds an absolute path");
      }
    } else if (node->is_object()) {
      for (auto it = node->begin(); it != node->end(); ++it) stack.emplace_back(&*it, where + "/" + it.key());
    } else if (node->is_array()) {
      for (size_t i = 0; i < node->size(); ++i) stack.emplace_back(&(*node)[i], where + "/" + std::to_string(i));
    }
  }
}

namespace {

ValidationReport validateSource(const detail::ByteSource& source, const ValidateOptions& options) {
  ValidationReport report;
  Collector collector(&report.messages);
  ReaderOptions reader_options;
  reader_options.max_raw_section_size = options.max_raw_section_size;
  detail::ParsedContainer parsed;
  report.status = detail::parseContainer(source, reader_options, &parsed, &collector);
  // Header errors, or an index that fails its checksum, leave nothing trustworthy to look at.
  const bool structure_unusable = std::any_of(
      report.messages.begin(), report.messages.end(),
      [](const ValidationMessage& m) { return m.severity == Severity::kError && (m.id < 3000 || m.id == 3001); });
  if (structure_unusable || parsed.sections.size() != parsed.header.section_count) return report;

  auto noteStatus = [&](ContainerStatus status) {
    if (report.status == ContainerStatus::kOk) report.status = status;
  };
  const auto& sections = parsed.sections;
  const AssetKind kind = AssetKind(parsed.header.asset_kind);
  const bool index_sound = report.status == ContainerStatus::kOk;

  // 4xxx: whole-file checksum, then every section's bytes.
  if (index_sound) {
    const ContainerStatus checksum = detail::verifyFileChecksumOf(source, parsed.header.file_checksum);
    if (checksum == ContainerStatus::kIoError) {
      addError(&report.messages, 1002, "cannot read the file");
      noteStatus(checksum);
    } else if (checksum != ContainerStatus::kOk) {
      addError(&report.messages, 4001, "whole-file checksum mismatch");
      noteStatus(checksum);
    }
  }
  std::string metadata_text;
  std::vector<bool> readable(sections.size(), false);
  WangRecord wang_record;  // the wang-tiles record, once seen and valid (its sections check against it)
  bool have_wang_record = false;
  TinyExampleSeen tiny;
  GlitterSeen glitter;
  for (size_t i = 0; i < sections.size(); ++i) {
    const SectionInfo& s = sections[i];
    if (!isRegisteredSectionType(s.type)) {
      addWarning(&report.messages, 3011, describe(i, s) + ": unknown section type, skipped by readers");
    }
    const bool known_codec = s.codec == uint32_t(Codec::kRaw) || s.codec == uint32_t(Codec::kZstd);
    if (!index_sound || !known_codec) continue;
    if (s.type == kSectionMetadata && s.raw_size > kMaxMetadataBytes) {
      // Refused from its declared size, before a byte of it is decoded.
      addError(&report.messages, 5016,
               describe(i, s) + ": metadata is " + std::to_string(s.raw_size) + " bytes, more than the 16 MiB limit");
      continue;
    }
    if (!options.check_payloads && s.type != kSectionMetadata) continue;
    // Streamed in bounded chunks (the frame is checked against raw_size first); only the metadata
    // and records of the right size are kept whole.
    const bool keep_whole =
        s.type == kSectionMetadata ||
        (s.type == kSectionWangEdges && have_wang_record && s.raw_size == wangEdgesBytes(wang_record)) ||
        (kind == AssetKind::kGlitter && s.type == kSectionGlitterIntegrals &&
         s.raw_size <= uint64_t(kMaxGlitterIntegrals) * sizeof(GlitterIntegral));
    Payload raw;
    PayloadSink sink(&raw, keep_whole);
    const ContainerStatus status = detail::streamSection(source, s, &sink);
    if (status == ContainerStatus::kChecksumMismatch) {
      addError(&report.messages, 4002, describe(i, s) + ": checksum mismatch");
    } else if (status == ContainerStatus::kDecompressFailed) {
      addError(&report.messages, 4003, describe(i, s) + ": zstd data does not decode to exactly raw_size bytes");
    } else if (status == ContainerStatus::kTooLarge) {
      addError(&report.messages, 4010, describe(i, s) + ": zstd frame window exceeds the reader limit of 128 MiB");
    } else if (status != ContainerStatus::kOk) {
      addError(&report.messages, 1002, describe(i, s) + ": cannot be read (" + statusString(status) + ")");
    }
    if (status != ContainerStatus::kOk) {
      noteStatus(status);
      continue;
    }
    readable[i] = true;
    if (s.type == kSectionMetadata) {
      if (metadata_text.empty()) metadata_text.assign(raw.whole.begin(), raw.whole.end());
      continue;
    }
    if (kind == AssetKind::kTinyExample) noteTinyExamplePayload(i, s, raw, &tiny, &report.messages);
    if (kind == AssetKind::kGlitter) noteGlitterPayload(i, s, raw, &glitter, &report.messages);
    if (s.type == kSectionFlakes) {
      checkFlakesPayload(i, s, raw, &report.messages);
    } else if (s.type >= kSectionWangInfo && s.type <= kSectionWangTileNdf) {
      checkWangPayload(i, s, raw, &wang_record, &have_wang_record, &report.messages);
    } else if (s.type == kSectionTinyExampleInfo || s.type == kSectionTinyExampleTexels ||
               s.type == kSectionTinyExampleLevelHalf || s.type == kSectionGlitterInfo ||
               s.type == kSectionGlitterIntegrals) {
      // Records, not images.
    } else if (s.type != kSectionMetadata) {
      checkImagePayload(i, s, raw, &report.messages);
    }
    if (s.type == kSectionNdfChunk) {
      ImageSectionHeader image;
      if (parseImageHeader(raw.head.data(), raw.size, &image) && image.width != image.height) {
        addWarning(&report.messages, 6003,
                   describe(i, s) + ": NDF images are " + std::to_string(image.width) + " x " +
                       std::to_string(image.height) + ", not square");
      }
    }
  }

  // 5xxx: the metadata section.
  size_t metadata_count = 0;
  for (const SectionInfo& s : sections) metadata_count += s.type == kSectionMetadata;
  if (metadata_count == 0) {
    addError(&report.messages, 5001, "no metadata section (type 1)");
  } else if (metadata_count > 1) {
    addError(&report.messages, 5002, std::to_string(metadata_count) + " metadata sections, expected exactly one");
  }
  for (size_t i = 0; i < sections.size(); ++i) {
    if (sections[i].type != kSectionMetadata || !readable[i]) continue;
    validateMetadata(metadata_text, kind, &report.messages);
    break;
  }

  // 6xxx: kind-specific.
  if (findKind(kind) == nullptr) {
    addWarning(&report.messages, 6001,
               "asset kind " + std::to_string(parsed.header.asset_kind) + " is not known to this version");
  }
  if (kind == AssetKind::kTinyExample && index_sound && options.check_payloads)
    checkTinyExampleLayout(sections, tiny, &report.messages);
  if (kind == AssetKind::kGlitter && index_sound && options.check_payloads)
    checkGlitterSections(glitter, &report.messages);
  uint32_t first = 0, last = 0;
  if (kindTypeRange(kind, &first, &last) && std::none_of(sections.begin(), sections.end(), [&](const SectionInfo& s) {
        return s.type >= first && s.type <= last;
      })) {
    addWarning(&report.messages, 6002,
               std::string("a ") + assetKindString(kind) + " asset holds no section of types " + std::to_string(first) +
                   "-" + std::to_string(last));
  }

  return report;
}

}  // namespace

ValidationReport validate(const void* data, size_t size, const ValidateOptions& options) {
  static const uint8_t kEmpty = 0;
  const detail::MemorySource source(data ? data : &kEmpty, data ? size : 0);
  return validateSource(source, options);
}

ValidationReport validateFile(const std::string& path, const ValidateOptions& options) {
  detail::FileSource source;
  if (!source.open(path)) {
    ValidationReport report;
    report.status = ContainerStatus::kIoError;
    report.messages.push_back({1001, Severity::kError, "cannot open the file for reading"});
    return report;
  }
  return validateSource(source, options);
}

}  // namespace glintbake::format
