// SPDX-License-Identifier: Apache-2.0
// Header and index checks shared by Reader::open() and validate(): one implementation of every
// structural rule of formats/SPEC.md, reporting either the first failure (reader) or every
// failure with its stable message id (validator). Private to the container library.
#pragma once

#include <glintbake/format/container.h>

#include "byte_source.h"

#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::format::detail {

// Receives findings. Ids are the stable validator ids listed in formats/SPEC.md ("Validation").
class Diagnostics {
 public:
  virtual ~Diagnostics() = default;
  virtual void error(int id, const std::string& message) = 0;
  virtual void warning(int id, const std::string& message) = 0;
};

struct ParsedContainer {
  HeaderInfo header;
  uint32_t header_flags = 0;
  uint64_t index_size = 0;
  uint64_t index_checksum = 0;
  std::vector<SectionInfo> sections;
};

// Reads and checks the header and the index of `source`. Without diagnostics, returns at the first
// failure. With diagnostics, reports every finding and still returns the first failing status;
// header failures stop the parse (later fields cannot be trusted), index entry failures do not.
// Never reads or allocates more than the source's size. Safe on untrusted input.
ContainerStatus parseContainer(const ByteSource& source, const ReaderOptions& options, ParsedContainer* out,
                               Diagnostics* diagnostics);

// Reads section `info` of `source` into dst (exactly info.raw_size bytes): checks its checksum,
// its codec and, for zstd, the frame (ZstdFrameScan) before decoding. `info` must come from
// parseContainer on the same source. A frame whose window exceeds kMaxZstdWindowSize is refused
// (kTooLarge) here too, although decoding into one buffer needs no window: every reader accepts
// the same files. Thread-safe.
ContainerStatus readSectionFrom(const ByteSource& source, const SectionInfo& info, void* dst, size_t dst_size);

// Same, into out (resized to raw_size only after the stored bytes have proven, checksum and zstd
// frame and block headers, that they decode to raw_size bytes). out is empty on failure.
ContainerStatus readSectionAlloc(const ByteSource& source, const SectionInfo& info, std::vector<uint8_t>* out);

// Checks the structure of a zstd frame from its stored bytes, fed in order in pieces of any size,
// without decoding it: one frame (RFC 8878) that is exactly the stored bytes, records raw_size as
// its content size, whose block headers can produce that many bytes (raw and RLE blocks their
// stated size, a compressed block at most 128 KiB; the header's content size is only a claim) and
// whose window is at most kMaxZstdWindowSize. Holds no more than a few bytes of the frame.
class ZstdFrameScan {
 public:
  explicit ZstdFrameScan(uint64_t stored_size) : stored_size_(stored_size) {}
  void feed(const uint8_t* data, size_t size);
  // After every stored byte was fed: kOk, kDecompressFailed (not such a frame) or kTooLarge (a
  // sound frame whose window exceeds kMaxZstdWindowSize).
  ContainerStatus verdict(uint64_t raw_size) const;

 private:
  void parseHeader();
  void walk(const uint8_t* piece, uint64_t piece_at, size_t size);

  enum class State { kHeader, kBlocks, kDone, kBad };
  static constexpr size_t kMaxFrameHeader = 18;  // ZSTD_FRAMEHEADERSIZE_MAX
  uint64_t stored_size_;
  uint64_t fed_ = 0;
  State state_ = State::kHeader;
  uint8_t head_[kMaxFrameHeader] = {};
  size_t head_size_ = 0;
  uint64_t content_size_ = 0;
  uint64_t window_size_ = 0;
  bool checksum_flag_ = false;
  uint64_t next_block_ = 0;  // frame offset of the next block header (kBlocks), or of the frame's end (kDone)
  uint8_t block_[3] = {};    // a block header split between two pieces
  size_t block_have_ = 0;
  uint64_t bound_ = 0;  // the most bytes the blocks walked so far can produce
};

// Decodes one section front to back: start() runs every check readSectionAlloc makes (checksum;
// for zstd, the frame by ZstdFrameScan) on the stored bytes, read in pieces of kSectionStreamChunk
// bytes; read() then decodes on demand. Memory: two pieces plus, for zstd, its decoding context and
// window (at most kMaxZstdWindowSize), whatever the section's size. Memory sources are used in
// place. Not thread-safe; one decoder per thread (decoders of one source may run concurrently).
class SectionDecoder {
 public:
  SectionDecoder() = default;
  ~SectionDecoder();
  SectionDecoder(const SectionDecoder&) = delete;
  SectionDecoder& operator=(const SectionDecoder&) = delete;

  // Checks section `info` (from parseContainer on `source`, which must outlive the decoder);
  // nothing is decoded yet. A zstd frame of raw_size 0 is decoded whole here.
  ContainerStatus start(const ByteSource& source, const SectionInfo& info);
  // The next min(size, remaining()) decoded bytes into dst. A frame that turns out not to decode
  // to exactly raw_size bytes fails the call that meets the problem (kDecompressFailed); the
  // failure sticks. The bytes of a failing call are unspecified.
  ContainerStatus read(void* dst, size_t size);
  // raw_size and the bytes not yet read of the section started, 0 when start() failed.
  uint64_t size() const { return started_ ? info_.raw_size : 0; }
  uint64_t remaining() const { return started_ ? info_.raw_size - produced_ : 0; }

 private:
  ContainerStatus fail(ContainerStatus status);
  bool refill();  // the next piece of stored bytes into in_; false at the end or on a failed read
  ContainerStatus pump(uint8_t* dst, size_t size);
  ContainerStatus finishFrame();

  const ByteSource* source_ = nullptr;
  SectionInfo info_;
  ContainerStatus status_ = ContainerStatus::kInvalidArgument;  // until start() succeeds
  uint64_t produced_ = 0;
  void* dctx_ = nullptr;  // ZSTD_DCtx, opaque here to keep zstd.h out of this header
  const uint8_t* in_data_ = nullptr;
  size_t in_size_ = 0, in_pos_ = 0;
  uint64_t stored_read_ = 0;    // stored bytes passed to in_ so far
  std::vector<uint8_t> piece_;  // file sources: the current piece of stored bytes
  bool io_failed_ = false;
  bool frame_done_ = false;
  bool started_ = false;
};

// Receives a section's decoded bytes in order, in pieces of at most kSectionStreamChunk bytes.
class SectionSink {
 public:
  virtual ~SectionSink() = default;
  virtual void consume(const uint8_t* data, size_t size) = 0;
};
constexpr size_t kSectionStreamChunk = size_t(1) << 20;

// The decoded bytes of section `info`, passed to `sink` in bounded pieces (a SectionDecoder)
// instead of one raw_size buffer, after the same checks and with the same statuses as
// readSectionAlloc. The sink may have seen bytes when a failure is returned (a frame that stops
// early): callers keep what it found only on kOk. Thread-safe.
ContainerStatus streamSection(const ByteSource& source, const SectionInfo& info, SectionSink* sink);

// Hashes bytes [kHeaderSize, size) of the source (streamed in fixed-size chunks) and compares
// with `expected`.
ContainerStatus verifyFileChecksumOf(const ByteSource& source, uint64_t expected);

}  // namespace glintbake::format::detail
