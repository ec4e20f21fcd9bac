// SPDX-License-Identifier: Apache-2.0
// Where a container's bytes come from: a caller-owned memory buffer or a file read with positioned
// reads. Private to the container library; shared by the reader and the validator so both run the
// same checks on the same bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace glintbake::format::detail {

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Total size in bytes, fixed for the source's lifetime.
  virtual uint64_t size() const = 0;
  // Copies [offset, offset + n) into dst; false on a short or failed read. Thread-safe.
  virtual bool readAt(uint64_t offset, void* dst, size_t n) const = 0;
  // Direct access for in-memory sources (zero-copy decoding), null for files.
  virtual const uint8_t* data() const { return nullptr; }
};

class MemorySource final : public ByteSource {
 public:
  MemorySource(const void* data, size_t size) : data_(static_cast<const uint8_t*>(data)), size_(size) {}
  uint64_t size() const override { return size_; }
  bool readAt(uint64_t offset, void* dst, size_t n) const override;
  const uint8_t* data() const override { return data_; }

 private:
  const uint8_t* data_;
  size_t size_;
};

// Owns a read-only file descriptor; reads with pread so concurrent readers need no lock.
class FileSource final : public ByteSource {
 public:
  FileSource() = default;
  ~FileSource() override;
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;
  // Opens path and records its size; false if it cannot be opened or is not a regular file.
  bool open(const std::string& path);
  uint64_t size() const override { return size_; }
  bool readAt(uint64_t offset, void* dst, size_t n) const override;

 private:
  int fd_ = -1;
  uint64_t size_ = 0;
};

}  // namespace glintbake::format::detail
