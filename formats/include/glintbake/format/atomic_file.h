// SPDX-License-Identifier: Apache-2.0
// Output files that appear at their path only when complete: the one write path of every glintbake
// writer (containers, images, tables, depfiles).
//
// The bytes go to an anonymous file in the destination directory (Linux O_TMPFILE), linked into
// place by commit(), so even SIGKILL leaves nothing behind. Where the file system cannot create
// anonymous files, they go to "<path>.tmp-XXXXXX" beside the destination instead, removed on any
// failure and by the signal handlers of the tools; such a file is left only by SIGKILL or a power
// loss, and any "<name>.tmp-*" beside an output is stale and may be deleted (README, "Outputs").
//
// Every write(), fsync(), close(), link and rename result is checked; the first failure is sticky
// and its errno is kept for the message (EFBIG for a file-size limit, ENOSPC, EIO). SIGXFSZ must be
// ignored by the process for a file-size limit to reach this error path (the tools do).
// Not thread-safe; distinct objects may be used from distinct threads.
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace glintbake::format {

class AtomicFile {
 public:
  AtomicFile() = default;
  ~AtomicFile();  // abort() unless commit() succeeded
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Creates the temporary file for `path` (mode 0644 less the umask). kIoError on failure.
  ContainerStatus open(const std::string& path);
  // Appends size bytes. kIoError on a short or failed write (the error stays).
  ContainerStatus write(const void* data, size_t size);
  // Writes size bytes at offset without moving the append position.
  ContainerStatus writeAt(const void* data, size_t size, uint64_t offset);
  // fsync, close, and link or rename the file to its path (replacing an existing file), then syncs
  // the directory (best effort). kIoError if anything failed before or now; the file is then removed.
  ContainerStatus commit();
  // Closes and removes the temporary file. Idempotent.
  void abort();

  // Named temporary file while open; empty for an anonymous one (nothing to clean up on a signal).
  const std::string& temporaryPath() const { return tmp_path_; }
  const std::string& path() const { return path_; }
  // errno of the first failure (0 when none).
  int errorNumber() const { return error_; }
  // "<path>: <strerror(errno)>" for messages.
  std::string errorMessage() const;

 private:
  ContainerStatus fail(int error_number);

  std::string path_, tmp_path_;
  int fd_ = -1;
  int error_ = 0;
  bool committed_ = false;
};

// Writes size bytes to path through an AtomicFile. On failure *error_message (if given) receives
// "<path>: <reason>" and nothing is left at path's temporary name; an existing file at path is kept.
ContainerStatus writeFileAtomically(const std::string& path, const void* data, size_t size,
                                    std::string* error_message = nullptr);

}  // namespace glintbake::format
