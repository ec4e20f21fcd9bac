// SPDX-License-Identifier: Apache-2.0
// Structural checks of a container's header and index (formats/SPEC.md, "Reader requirements").
#include "container_parse.h"

#include "layout.h"

#define ZSTD_STATIC_LINKING_ONLY  // ZSTD_frameHeaderSize (exported by libzstd 1.4+)
#include <zstd.h>

#include "hash_stream.h"

#include <xxhash.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace glintbake::format::detail {
namespace {

using namespace layout;

std::string hex64(uint64_t v) {
  static const char* kDigits = "0123456789abcdef";
  std::string s = "0x";
  for (int shift = 60; shift >= 0; shift -= 4) s += kDigits[(v >> shift) & 0xF];
  return s;
}

// Collects findings; remembers the first failing status.
class Checker {
 public:
  explicit Checker(Diagnostics* diagnostics) : diagnostics_(diagnostics) {}

  // Records an error; returns true if parsing should stop now (no diagnostics sink).
  bool fail(ContainerStatus status, int id, const std::string& message) {
    if (first_ == ContainerStatus::kOk) first_ = status;
    if (diagnostics_) diagnostics_->error(id, message);
    return diagnostics_ == nullptr;
  }
  void warn(int id, const std::string& message) {
    if (diagnostics_) diagnostics_->warning(id, message);
  }
  ContainerStatus status() const { return first_; }

 private:
  Diagnostics* diagnostics_;
  ContainerStatus first_ = ContainerStatus::kOk;
};

bool allZero(const uint8_t* p, size_t n) {
  return std::all_of(p, p + n, [](uint8_t b) { return b == 0; });
}

ContainerStatus parseHeader(const ByteSource& source, ParsedContainer* out, Checker& check) {
  const uint64_t actual_size = source.size();
  uint8_t h[kHeaderSize];
  const size_t head = size_t(std::min<uint64_t>(actual_size, kHeaderSize));
  if (!source.readAt(0, h, head)) {
    check.fail(ContainerStatus::kIoError, 1002, "cannot read the file header");
    return check.status();
  }
  // Magic first: a short file that is not a container is "not a container", not "truncated".
  if (std::memcmp(h, kMagic, std::min<size_t>(head, sizeof(kMagic))) != 0) {
    check.fail(ContainerStatus::kBadMagic, 2002, "not a glintbake container (bad magic bytes)");
    return check.status();
  }
  if (head < kHeaderSize) {
    check.fail(ContainerStatus::kTruncated, 2001,
               "file is " + std::to_string(actual_size) + " bytes, shorter than the 128-byte header");
    return check.status();
  }

  HeaderInfo& hi = out->header;
  hi.version_major = load16(h + kOffVersionMajor);
  hi.version_minor = load16(h + kOffVersionMinor);
  // The version decides how the rest is laid out, so it is checked before the checksum.
  if (hi.version_major != kFormatVersionMajor) {
    const std::string v = std::to_string(hi.version_major) + "." + std::to_string(hi.version_minor);
    const std::string mine = std::to_string(kFormatVersionMajor) + "." + std::to_string(kFormatVersionMinor);
    if (hi.version_major > kFormatVersionMajor) {
      check.fail(ContainerStatus::kUnsupportedVersion, 2003,
                 "container format " + v + " is newer than this reader (" + mine + "); upgrade glintbake");
    } else {
      check.fail(ContainerStatus::kUnsupportedVersion, 2004, "container format " + v + " is not a released version");
    }
    return check.status();
  }

  uint8_t zeroed[kHeaderSize];
  std::memcpy(zeroed, h, kHeaderSize);
  std::memset(zeroed + kOffHeaderChecksum, 0, 8);
  const uint64_t header_checksum = load64(h + kOffHeaderChecksum);
  const uint64_t computed = hash64(zeroed, kHeaderSize);
  if (computed != header_checksum) {
    check.fail(ContainerStatus::kCorruptHeader, 2005,
               "header checksum mismatch (stored " + hex64(header_checksum) + ", computed " + hex64(computed) + ")");
    return check.status();
  }
  if (hi.version_minor > kFormatVersionMinor) {
    check.warn(2014, "container format 1." + std::to_string(hi.version_minor) + " is newer than this reader (1." +
                         std::to_string(kFormatVersionMinor) + "); sections of unknown types are skipped");
  }

  hi.asset_kind = load32(h + kOffAssetKind);
  const uint32_t header_size = load32(h + kOffHeaderSize);
  out->header_flags = load32(h + kOffFlags);
  hi.section_count = load32(h + kOffSectionCount);
  hi.index_offset = load64(h + kOffIndexOffset);
  out->index_size = load64(h + kOffIndexSize);
  hi.file_size = load64(h + kOffFileSize);
  hi.file_checksum = load64(h + kOffFileChecksum);
  out->index_checksum = load64(h + kOffIndexChecksum);

  if (header_size != kHeaderSize) {
    check.fail(ContainerStatus::kCorruptHeader, 2006,
               "header_size is " + std::to_string(header_size) + ", expected 128");
    return check.status();
  }
  if (out->header_flags != 0 || load32(h + kOffHeaderReserved) != 0 ||
      !allZero(h + kOffHeaderPadding, kHeaderSize - kOffHeaderPadding)) {
    check.warn(2013, "reserved header fields or padding are not zero");
  }
  if (hi.section_count > kMaxSectionCount) {
    check.fail(ContainerStatus::kTooLarge, 2007,
               "section_count " + std::to_string(hi.section_count) + " exceeds the reader limit " +
                   std::to_string(kMaxSectionCount));
    return check.status();
  }
  if (out->index_size != uint64_t(hi.section_count) * kIndexEntrySize) {
    check.fail(ContainerStatus::kCorruptHeader, 2008,
               "index_size " + std::to_string(out->index_size) + " does not match section_count " +
                   std::to_string(hi.section_count) + " x 64");
    return check.status();
  }
  if (hi.index_offset < kHeaderSize || hi.index_offset % kSectionAlignment != 0) {
    check.fail(ContainerStatus::kCorruptHeader, 2009,
               "index_offset " + std::to_string(hi.index_offset) + " is not a multiple of 64 at or after the header");
    return check.status();
  }
  if (hi.index_offset > UINT64_MAX - out->index_size || hi.index_offset + out->index_size != hi.file_size) {
    check.fail(ContainerStatus::kCorruptHeader, 2010,
               "file_size " + std::to_string(hi.file_size) + " is not index_offset + index_size");
    return check.status();
  }
  if (actual_size < hi.file_size) {
    check.fail(
        ContainerStatus::kTruncated, 2011,
        "file is truncated: " + std::to_string(actual_size) + " bytes, header says " + std::to_string(hi.file_size));
    return check.status();
  }
  if (actual_size > hi.file_size) {
    check.fail(ContainerStatus::kCorruptHeader, 2012,
               "file has " + std::to_string(actual_size - hi.file_size) + " trailing bytes after the index");
    return check.status();
  }
  return check.status();
}

void parseIndex(const ByteSource& source, const ReaderOptions& options, ParsedContainer* out, Checker& check) {
  const HeaderInfo& hi = out->header;
  // index_size <= file size was established by parseHeader, so this allocation is bounded by the file.
  std::vector<uint8_t> index(size_t(out->index_size));
  if (!source.readAt(hi.index_offset, index.data(), index.size())) {
    check.fail(ContainerStatus::kIoError, 1002, "cannot read the section index");
    return;
  }
  const uint64_t computed = hash64(index.data(), index.size());
  if (computed != out->index_checksum) {
    check.fail(ContainerStatus::kCorruptIndex, 3001,
               "index checksum mismatch (stored " + hex64(out->index_checksum) + ", computed " + hex64(computed) + ")");
    return;
  }

  out->sections.resize(hi.section_count);
  bool nonzero_reserved = false;
  for (uint32_t i = 0; i < hi.section_count; ++i) {
    const uint8_t* e = index.data() + size_t(i) * kIndexEntrySize;
    SectionInfo& s = out->sections[i];
    s.type = load32(e + kEntType);
    s.codec = load32(e + kEntCodec);
    s.key = load64(e + kEntKey);
    s.offset = load64(e + kEntOffset);
    s.stored_size = load64(e + kEntStoredSize);
    s.raw_size = load64(e + kEntRawSize);
    s.checksum = load64(e + kEntChecksum);
    s.flags = load32(e + kEntFlags);
    s.reserved = load32(e + kEntReserved);
    if (s.flags != 0 || s.reserved != 0 || !allZero(e + kEntPadding, kIndexEntrySize - kEntPadding)) {
      nonzero_reserved = true;
    }

    const std::string name = "section " + std::to_string(i);
    if (s.offset % kSectionAlignment != 0) {
      if (check.fail(ContainerStatus::kCorruptIndex, 3002,
                     name + ": offset " + std::to_string(s.offset) + " is not a multiple of 64"))
        return;
    }
    if (s.offset < kHeaderSize || s.offset > hi.index_offset || s.stored_size > hi.index_offset - s.offset) {
      if (check.fail(ContainerStatus::kCorruptIndex, 3003,
                     name + ": bytes [" + std::to_string(s.offset) + ", +" + std::to_string(s.stored_size) +
                         ") lie outside the section area [128, " + std::to_string(hi.index_offset) + ")"))
        return;
    }
    if (s.raw_size > options.max_raw_section_size) {
      if (check.fail(ContainerStatus::kTooLarge, 3005,
                     name + ": raw size " + std::to_string(s.raw_size) + " exceeds the reader limit " +
                         std::to_string(options.max_raw_section_size)))
        return;
    }
    if (s.codec == uint32_t(Codec::kRaw)) {
      if (s.stored_size != s.raw_size) {
        if (check.fail(ContainerStatus::kCorruptIndex, 3006, name + ": raw codec but stored_size != raw_size")) return;
      }
    } else if (s.codec == uint32_t(Codec::kZstd)) {
      // ZSTD_compressBound is only meaningful below ZSTD_MAX_INPUT_SIZE; the cap above keeps
      // raw_size small enough on 64-bit hosts, the explicit test covers the rest.
      const size_t bound = s.raw_size <= uint64_t(SIZE_MAX / 2) ? ZSTD_compressBound(size_t(s.raw_size)) : 0;
      if (s.stored_size == 0 || bound == 0 || ZSTD_isError(bound) || s.stored_size > bound) {
        if (check.fail(ContainerStatus::kCorruptIndex, 3007,
                       name + ": zstd stored_size " + std::to_string(s.stored_size) + " is impossible for raw_size " +
                           std::to_string(s.raw_size)))
          return;
      }
    } else {
      check.warn(3009, name + ": unknown codec " + std::to_string(s.codec) + " (section cannot be read)");
    }
  }
  if (nonzero_reserved) check.warn(3010, "reserved index entry fields or padding are not zero");

  // No two sections may share bytes, and (type, key) identifies a section uniquely.
  std::vector<uint32_t> order(out->sections.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto& secs = out->sections;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return secs[a].offset != secs[b].offset ? secs[a].offset < secs[b].offset : a < b;
  });
  for (size_t k = 1; k < order.size(); ++k) {
    const SectionInfo& prev = secs[order[k - 1]];
    const SectionInfo& cur = secs[order[k]];
    if (prev.stored_size == 0 || cur.stored_size == 0) continue;  // empty sections occupy no bytes
    if (prev.offset <= UINT64_MAX - prev.stored_size && prev.offset + prev.stored_size > cur.offset) {
      if (check.fail(ContainerStatus::kCorruptIndex, 3004,
                     "sections " + std::to_string(order[k - 1]) + " and " + std::to_string(order[k]) + " overlap"))
        return;
    }
  }
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    if (secs[a].type != secs[b].type) return secs[a].type < secs[b].type;
    if (secs[a].key != secs[b].key) return secs[a].key < secs[b].key;
    return a < b;
  });
  for (size_t k = 1; k < order.size(); ++k) {
    const SectionInfo& prev = secs[order[k - 1]];
    const SectionInfo& cur = secs[order[k]];
    if (prev.type == cur.type && prev.key == cur.key) {
      if (check.fail(ContainerStatus::kCorruptIndex, 3008,
                     "sections " + std::to_string(order[k - 1]) + " and " + std::to_string(order[k]) +
                         " have the same type " + std::to_string(cur.type) + " and key " + std::to_string(cur.key)))
        return;
    }
  }
}

}  // namespace

ContainerStatus parseContainer(const ByteSource& source, const ReaderOptions& options, ParsedContainer* out,
                               Diagnostics* diagnostics) {
  *out = ParsedContainer{};
  Checker check(diagnostics);
  if (parseHeader(source, out, check) != ContainerStatus::kOk) return check.status();
  parseIndex(source, options, out, check);
  if (check.status() != ContainerStatus::kOk && diagnostics == nullptr) out->sections.clear();
  return check.status();
}

namespace {

// The stored bytes of a zstd section, checksum-verified and proven (ZstdFrameScan) to decode to
// exactly raw_size within the window limit. Memory sources are used in place; file sources go
// through `buffer` (bounded by the file's size). Nothing of raw_size is allocated here.
ContainerStatus loadZstdFrame(const ByteSource& source, const SectionInfo& info, std::vector<uint8_t>* buffer,
                              const uint8_t** stored_out) {
  const uint8_t* stored = source.data() ? source.data() + info.offset : nullptr;
  if (!stored) {
    if (info.stored_size > source.size()) return ContainerStatus::kTruncated;
    buffer->resize(size_t(info.stored_size));
    if (!source.readAt(info.offset, buffer->data(), buffer->size())) return ContainerStatus::kTruncated;
    stored = buffer->data();
  } else if (info.offset > source.size() || info.stored_size > source.size() - info.offset) {
    return ContainerStatus::kTruncated;
  }
  const size_t stored_size = size_t(info.stored_size);
  if (hash64(stored, stored_size) != info.checksum) return ContainerStatus::kChecksumMismatch;
  ZstdFrameScan scan(info.stored_size);
  scan.feed(stored, stored_size);
  const ContainerStatus status = scan.verdict(info.raw_size);
  if (status != ContainerStatus::kOk) return status;
  *stored_out = stored;
  return ContainerStatus::kOk;
}

ContainerStatus decodeZstd(const uint8_t* stored, size_t stored_size, void* dst, size_t dst_size) {
  ZSTD_DCtx* dctx = ZSTD_createDCtx();
  if (!dctx) return ContainerStatus::kDecompressFailed;
  const size_t got = ZSTD_decompressDCtx(dctx, dst, dst_size, stored, stored_size);
  ZSTD_freeDCtx(dctx);
  if (ZSTD_isError(got) || got != dst_size) return ContainerStatus::kDecompressFailed;
  return ContainerStatus::kOk;
}

ContainerStatus readRaw(const ByteSource& source, const SectionInfo& info, void* dst, size_t dst_size) {
  if (info.stored_size != info.raw_size) return ContainerStatus::kCorruptIndex;
  if (!source.readAt(info.offset, dst, dst_size)) return ContainerStatus::kTruncated;
  if (hash64(dst, dst_size) != info.checksum) return ContainerStatus::kChecksumMismatch;
  return ContainerStatus::kOk;
}

bool knownCodec(uint32_t codec) { return codec == uint32_t(Codec::kRaw) || codec == uint32_t(Codec::kZstd); }

}  // namespace

ContainerStatus readSectionFrom(const ByteSource& source, const SectionInfo& info, void* dst, size_t dst_size) {
  if (dst_size != info.raw_size || (dst == nullptr && dst_size != 0)) return ContainerStatus::kInvalidArgument;
  if (!knownCodec(info.codec)) return ContainerStatus::kDecompressFailed;
  if (info.codec == uint32_t(Codec::kRaw)) return readRaw(source, info, dst, dst_size);
  std::vector<uint8_t> buffer;
  const uint8_t* stored = nullptr;
  const ContainerStatus status = loadZstdFrame(source, info, &buffer, &stored);
  if (status != ContainerStatus::kOk) return status;
  return decodeZstd(stored, size_t(info.stored_size), dst, dst_size);
}

ContainerStatus readSectionAlloc(const ByteSource& source, const SectionInfo& info, std::vector<uint8_t>* out) {
  out->clear();
  if (!knownCodec(info.codec)) return ContainerStatus::kDecompressFailed;
  if (info.codec == uint32_t(Codec::kRaw)) {
    // stored_size = raw_size and the stored bytes lie inside the file (parseContainer).
    if (info.stored_size != info.raw_size || info.raw_size > source.size()) return ContainerStatus::kCorruptIndex;
    out->resize(size_t(info.raw_size));
    const ContainerStatus status = readRaw(source, info, out->data(), out->size());
    if (status != ContainerStatus::kOk) out->clear();
    return status;
  }
  std::vector<uint8_t> buffer;
  const uint8_t* stored = nullptr;
  ContainerStatus status = loadZstdFrame(source, info, &buffer, &stored);
  if (status != ContainerStatus::kOk) return status;
  out->resize(size_t(info.raw_size));
  status = decodeZstd(stored, size_t(info.stored_size), out->data(), out->size());
  if (status != ContainerStatus::kOk) std::vector<uint8_t>().swap(*out);
  return status;
}

void ZstdFrameScan::feed(const uint8_t* data, size_t size) {
  const uint64_t at = fed_;
  fed_ += size;
  size_t used = 0;
  if (state_ == State::kHeader) {
    used = std::min(size, kMaxFrameHeader - head_size_);
    std::memcpy(head_ + head_size_, data, used);
    head_size_ += used;
    if (head_size_ < kMaxFrameHeader && fed_ < stored_size_) return;
    parseHeader();
    walk(head_, 0, head_size_);  // the first blocks may start inside the header's piece
  }
  walk(data + used, at + used, size - used);
}

void ZstdFrameScan::parseHeader() {
  ZSTD_frameHeader fh;
  if (ZSTD_getFrameHeader(&fh, head_, head_size_) != 0 || fh.frameType != ZSTD_frame) {
    state_ = State::kBad;
    return;
  }
  content_size_ = fh.frameContentSize;  // ZSTD_CONTENTSIZE_UNKNOWN when the header has none
  window_size_ = fh.windowSize;
  checksum_flag_ = fh.checksumFlag != 0;
  next_block_ = fh.headerSize;
  state_ = State::kBlocks;
}

// Block headers (RFC 8878 3.1.1.2): 3 bytes, bit 0 last block, bits 1-2 type (0 raw, 1 RLE,
// 2 compressed, 3 reserved), bits 3-23 size; an RLE block stores one byte.
void ZstdFrameScan::walk(const uint8_t* piece, uint64_t piece_at, size_t size) {
  constexpr uint64_t kMaxBlock = uint64_t(128) << 10;
  const uint64_t end = piece_at + size;
  while (state_ == State::kBlocks) {
    uint64_t want = next_block_ + block_have_;  // the next header byte needed
    if (want >= end) return;
    if (want < piece_at) {  // cannot happen: pieces arrive in order, each header byte once
      state_ = State::kBad;
      return;
    }
    while (block_have_ < 3 && want < end) block_[block_have_++] = piece[size_t(want++ - piece_at)];
    if (block_have_ < 3) return;
    block_have_ = 0;
    const uint32_t block = uint32_t(block_[0]) | uint32_t(block_[1]) << 8 | uint32_t(block_[2]) << 16;
    const uint32_t type = (block >> 1) & 3, block_size = block >> 3;
    if (type == 3 || block_size > kMaxBlock) {
      state_ = State::kBad;
      return;
    }
    next_block_ += 3 + (type == 1 ? 1 : block_size);
    bound_ += type == 2 ? kMaxBlock : block_size;
    if (block & 1) state_ = State::kDone;
  }
}

ContainerStatus ZstdFrameScan::verdict(uint64_t raw_size) const {
  if (state_ != State::kDone || fed_ != stored_size_) return ContainerStatus::kDecompressFailed;
  // Exactly one frame, exactly the stored bytes (its optional 4-byte checksum last).
  if (next_block_ + (checksum_flag_ ? 4 : 0) != stored_size_) return ContainerStatus::kDecompressFailed;
  if (content_size_ != raw_size || bound_ < raw_size) return ContainerStatus::kDecompressFailed;
  if (window_size_ > kMaxZstdWindowSize) return ContainerStatus::kTooLarge;
  return ContainerStatus::kOk;
}

ContainerStatus verifyFileChecksumOf(const ByteSource& source, uint64_t expected) {
  const uint64_t size = source.size();
  if (size < kHeaderSize) return ContainerStatus::kTruncated;
  uint64_t actual = 0;
  if (const uint8_t* data = source.data()) {
    actual = hash64(data + kHeaderSize, size_t(size - kHeaderSize));
  } else {
    XXH3Streamer hasher;
    if (!hasher.ok()) return ContainerStatus::kIoError;
    std::vector<uint8_t> chunk(size_t(1) << 20);
    for (uint64_t offset = kHeaderSize; offset < size;) {
      const size_t n = size_t(std::min<uint64_t>(chunk.size(), size - offset));
      if (!source.readAt(offset, chunk.data(), n)) return ContainerStatus::kIoError;
      hasher.update(chunk.data(), n);
      offset += n;
    }
    actual = hasher.digest();
  }
  return actual == expected ? ContainerStatus::kOk : ContainerStatus::kChecksumMismatch;
}

}  // namespace glintbake::format::detail
