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

// Hashes bytes [kHeaderSize, size) of the source (streamed in fixed-size chunks) and compares
// with `expected`.
ContainerStatus verifyFileChecksumOf(const ByteSource& source, uint64_t expected);

}  // namespace glintbake::format::detail
