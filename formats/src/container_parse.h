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
// its codec and, for zstd, that it is one frame whose recorded content size equals raw_size
// before decoding. `info` must come from parseContainer on the same source. Thread-safe.
ContainerStatus readSectionFrom(const ByteSource& source, const SectionInfo& info, void* dst, size_t dst_size);

// Same, into out (resized to raw_size only after the stored bytes have proven, checksum and zstd
// frame and block headers, that they decode to raw_size bytes). out is empty on failure.
ContainerStatus readSectionAlloc(const ByteSource& source, const SectionInfo& info, std::vector<uint8_t>* out);

// Receives a section's decoded bytes in order, in pieces of at most kSectionStreamChunk bytes.
class SectionSink {
 public:
  virtual ~SectionSink() = default;
  virtual void consume(const uint8_t* data, size_t size) = 0;
};
constexpr size_t kSectionStreamChunk = size_t(1) << 20;

// The decoded bytes of section `info`, passed to `sink` in bounded pieces instead of one raw_size
// buffer, after the same checks and with the same statuses as readSectionAlloc: raw sections are
// hashed, then read, a chunk at a time; zstd frames are decoded a chunk at a time with a window of
// at most 2^27 bytes (frames of larger windows made only of raw and RLE blocks, which need no
// window, are expanded block by block; any other such frame is decoded whole, as by
// readSectionAlloc). The stored bytes of a zstd section are read whole (they are in the file). The
// sink may have seen bytes when a failure is returned (a frame that stops early): callers keep
// what it found only on kOk. Thread-safe.
ContainerStatus streamSection(const ByteSource& source, const SectionInfo& info, SectionSink* sink);

// Hashes bytes [kHeaderSize, size) of the source (streamed in fixed-size chunks) and compares
// with `expected`.
ContainerStatus verifyFileChecksumOf(const ByteSource& source, uint64_t expected);

}  // namespace glintbake::format::detail
