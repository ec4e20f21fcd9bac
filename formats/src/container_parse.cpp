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

// The most bytes a zstd frame's blocks can produce, from its block headers alone (RFC 8878 3.1.1.2):
// raw and RLE blocks their stated size, a compressed block at most 128 KiB. The frame header's
// content size is a claim; this bound is what a hostile frame can really make a decoder write.
// UINT64_MAX when the block headers are malformed.
uint64_t zstdBlockBound(const uint8_t* frame, size_t size) {
  const size_t header = ZSTD_frameHeaderSize(frame, size);
  if (ZSTD_isError(header) || header > size) return UINT64_MAX;
  constexpr uint64_t kMaxBlock = uint64_t(128) << 10;
  uint64_t bound = 0;
  for (size_t at = header;;) {
    if (size - at < 3) return UINT64_MAX;
    const uint32_t block = uint32_t(frame[at]) | uint32_t(frame[at + 1]) << 8 | uint32_t(frame[at + 2]) << 16;
    at += 3;
    const uint32_t type = (block >> 1) & 3, block_size = block >> 3;
    const uint64_t consumed = type == 1 ? 1 : block_size;  // RLE: one byte repeated
    if (type == 3 || block_size > kMaxBlock || consumed > size - at) return UINT64_MAX;
    at += size_t(consumed);
    bound += type == 2 ? kMaxBlock : block_size;
    if (block & 1) return bound;
  }
}

// The stored bytes of a zstd section, checksum-verified and proven to decode to exactly raw_size:
// one frame, exactly the stored bytes, recording raw_size as its content size, whose blocks can
// produce that many bytes. Memory sources are used in place; file sources go through `buffer`
// (bounded by the file's size). Nothing of raw_size is allocated here.
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
  const size_t frame_size = ZSTD_findFrameCompressedSize(stored, stored_size);
  if (ZSTD_isError(frame_size) || frame_size != stored_size) return ContainerStatus::kDecompressFailed;
  const unsigned long long content = ZSTD_getFrameContentSize(stored, stored_size);
  if (content == ZSTD_CONTENTSIZE_UNKNOWN || content == ZSTD_CONTENTSIZE_ERROR || content != info.raw_size) {
    return ContainerStatus::kDecompressFailed;
  }
  // The frame header may lie; the block headers bound what the frame can really produce.
  const uint64_t bound = zstdBlockBound(stored, stored_size);
  if (bound == UINT64_MAX || bound < info.raw_size) return ContainerStatus::kDecompressFailed;
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

namespace {

constexpr int kStreamWindowLog = 27;  // ZSTD_WINDOWLOG_LIMIT_DEFAULT: the largest window streamed

// Raw sections: hashed a chunk at a time (nothing reaches the sink on a mismatch), then read again.
ContainerStatus streamRaw(const ByteSource& source, const SectionInfo& info, SectionSink* sink) {
  if (info.stored_size != info.raw_size || info.raw_size > source.size()) return ContainerStatus::kCorruptIndex;
  if (const uint8_t* data = source.data()) {
    if (info.offset > source.size() || info.raw_size > source.size() - info.offset) return ContainerStatus::kTruncated;
    const uint8_t* bytes = data + info.offset;
    if (hash64(bytes, size_t(info.raw_size)) != info.checksum) return ContainerStatus::kChecksumMismatch;
    for (uint64_t at = 0; at < info.raw_size; at += kSectionStreamChunk)
      sink->consume(bytes + at, size_t(std::min<uint64_t>(kSectionStreamChunk, info.raw_size - at)));
    return ContainerStatus::kOk;
  }
  std::vector<uint8_t> chunk(size_t(std::min<uint64_t>(kSectionStreamChunk, info.raw_size)));
  XXH3Streamer hasher;
  if (!hasher.ok()) return ContainerStatus::kIoError;
  for (uint64_t at = 0; at < info.raw_size;) {
    const size_t n = size_t(std::min<uint64_t>(chunk.size(), info.raw_size - at));
    if (!source.readAt(info.offset + at, chunk.data(), n)) return ContainerStatus::kTruncated;
    hasher.update(chunk.data(), n);
    at += n;
  }
  if (hasher.digest() != info.checksum) return ContainerStatus::kChecksumMismatch;
  for (uint64_t at = 0; at < info.raw_size;) {
    const size_t n = size_t(std::min<uint64_t>(chunk.size(), info.raw_size - at));
    if (!source.readAt(info.offset + at, chunk.data(), n)) return ContainerStatus::kTruncated;
    sink->consume(chunk.data(), n);
    at += n;
  }
  return ContainerStatus::kOk;
}

// A checked frame (loadZstdFrame) decoded by zstd's streaming decoder into one reused chunk.
ContainerStatus streamZstdFrame(const uint8_t* stored, size_t stored_size, uint64_t raw_size, SectionSink* sink) {
  ZSTD_DCtx* dctx = ZSTD_createDCtx();
  if (!dctx) return ContainerStatus::kDecompressFailed;
  ZSTD_DCtx_setParameter(dctx, ZSTD_d_windowLogMax, kStreamWindowLog);
  std::vector<uint8_t> chunk(size_t(std::min<uint64_t>(kSectionStreamChunk, std::max<uint64_t>(raw_size, 1))));
  ZSTD_inBuffer in{stored, stored_size, 0};
  uint64_t total = 0;
  ContainerStatus status = ContainerStatus::kDecompressFailed;
  for (;;) {
    ZSTD_outBuffer out{chunk.data(), chunk.size(), 0};
    const size_t left = ZSTD_decompressStream(dctx, &out, &in);
    if (ZSTD_isError(left) || out.pos > raw_size - total) break;
    total += out.pos;
    if (out.pos > 0) sink->consume(chunk.data(), out.pos);
    if (left == 0) {
      if (in.pos == in.size && total == raw_size) status = ContainerStatus::kOk;
      break;
    }
    if (in.pos == in.size && out.pos < out.size) break;  // the frame needs bytes it does not have
  }
  ZSTD_freeDCtx(dctx);
  return status;
}

// A checked frame whose blocks are all raw or RLE (checked here, false otherwise): expanded block
// by block, so its window size does not matter. Same verdicts as zstd's own decoder on such frames.
bool rawAndRleOnly(const uint8_t* frame, size_t size, size_t header) {
  for (size_t at = header; size - at >= 3;) {
    const uint32_t block = uint32_t(frame[at]) | uint32_t(frame[at + 1]) << 8 | uint32_t(frame[at + 2]) << 16;
    const uint32_t type = (block >> 1) & 3;
    if (type != 0 && type != 1) return false;
    const size_t consumed = type == 1 ? 1 : size_t(block >> 3);
    if (consumed > size - at - 3) return false;
    at += 3 + consumed;
    if (block & 1) return true;
  }
  return false;
}

ContainerStatus expandRawAndRle(const uint8_t* frame, size_t size, const ZSTD_frameHeader& fh, uint64_t raw_size,
                                SectionSink* sink) {
  std::vector<uint8_t> run;
  XXH64_state_t* xxh = XXH64_createState();
  if (!xxh) return ContainerStatus::kDecompressFailed;
  XXH64_reset(xxh, 0);
  uint64_t total = 0;
  size_t at = fh.headerSize;
  bool last = false;
  while (!last) {  // rawAndRleOnly proved every header and block lies inside the frame
    const uint32_t block = uint32_t(frame[at]) | uint32_t(frame[at + 1]) << 8 | uint32_t(frame[at + 2]) << 16;
    at += 3;
    last = block & 1;
    const bool rle = ((block >> 1) & 3) == 1;
    const size_t n = size_t(block >> 3);
    if (n > raw_size - total) break;
    const uint8_t* bytes = frame + at;
    if (rle) {
      run.assign(n, frame[at]);
      bytes = run.data();
    }
    XXH64_update(xxh, bytes, n);
    sink->consume(bytes, n);
    total += n;
    at += rle ? 1 : n;
  }
  const uint64_t digest = XXH64_digest(xxh);
  XXH64_freeState(xxh);
  if (!last || total != raw_size) return ContainerStatus::kDecompressFailed;
  const size_t end = at + (fh.checksumFlag ? 4 : 0);
  if (end != size) return ContainerStatus::kDecompressFailed;
  if (fh.checksumFlag && layout::load32(frame + at) != uint32_t(digest)) return ContainerStatus::kDecompressFailed;
  return ContainerStatus::kOk;
}

}  // namespace

ContainerStatus streamSection(const ByteSource& source, const SectionInfo& info, SectionSink* sink) {
  if (!knownCodec(info.codec)) return ContainerStatus::kDecompressFailed;
  if (info.codec == uint32_t(Codec::kRaw)) return streamRaw(source, info, sink);
  std::vector<uint8_t> buffer;
  const uint8_t* stored = nullptr;
  ContainerStatus status = loadZstdFrame(source, info, &buffer, &stored);
  if (status != ContainerStatus::kOk) return status;
  const size_t stored_size = size_t(info.stored_size);
  ZSTD_frameHeader fh;
  const bool plain = ZSTD_getFrameHeader(&fh, stored, stored_size) == 0 && fh.frameType == ZSTD_frame && fh.dictID == 0;
  if (plain && fh.windowSize <= (uint64_t(1) << kStreamWindowLog))
    return streamZstdFrame(stored, stored_size, info.raw_size, sink);
  if (plain && rawAndRleOnly(stored, stored_size, fh.headerSize))
    return expandRawAndRle(stored, stored_size, fh, info.raw_size, sink);
  // Anything else (a window above 2^27 with compressed blocks): decoded whole, as readSectionAlloc.
  std::vector<uint8_t> whole(size_t(info.raw_size));
  status = decodeZstd(stored, stored_size, whole.data(), whole.size());
  if (status != ContainerStatus::kOk) return status;
  for (size_t at = 0; at < whole.size(); at += kSectionStreamChunk)
    sink->consume(whole.data() + at, std::min(kSectionStreamChunk, whole.size() - at));
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
