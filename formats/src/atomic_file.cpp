// SPDX-License-Identifier: Apache-2.0
// AtomicFile: anonymous (O_TMPFILE) or named temporary file, checked writes, link/rename into place.
#include <glintbake/format/atomic_file.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace glintbake::format {
namespace {

std::string directoryOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// A fresh "<path>.tmp-xxxxxxxx" name (not created).
std::string randomSibling(const std::string& path) {
  static thread_local std::mt19937 rng{std::random_device{}()};
  char suffix[16];
  std::snprintf(suffix, sizeof(suffix), "%08x", unsigned(rng()));
  return path + ".tmp-" + suffix;
}

void syncDirectory(const std::string& path) {
  const int dir_fd = ::open(directoryOf(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

}  // namespace

AtomicFile::~AtomicFile() {
  if (!committed_) abort();
}

ContainerStatus AtomicFile::fail(int error_number) {
  if (error_ == 0) error_ = error_number ? error_number : EIO;
  return ContainerStatus::kIoError;
}

ContainerStatus AtomicFile::open(const std::string& path) {
  if (fd_ >= 0 || path.empty()) return ContainerStatus::kInvalidArgument;
  path_ = path;
  error_ = 0;
  committed_ = false;
#ifdef O_TMPFILE
  // Anonymous first; linking it into place later needs /proc/self/fd.
  if (::access("/proc/self/fd", X_OK) == 0) {
    fd_ = ::open(directoryOf(path).c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
  }
#endif
  if (fd_ < 0) {
    std::string pattern = path + ".tmp-XXXXXX";
    std::vector<char> buffer(pattern.begin(), pattern.end());
    buffer.push_back('\0');
    fd_ = ::mkstemp(buffer.data());
    if (fd_ < 0) return fail(errno);
    tmp_path_ = buffer.data();
  }
  // Assets are ordinary shareable files (mkstemp creates 0600).
  ::fchmod(fd_, 0644);
  return ContainerStatus::kOk;
}

ContainerStatus AtomicFile::write(const void* data, size_t size) {
  if (fd_ < 0) return fail(EBADF);
  if (error_) return ContainerStatus::kIoError;
  const auto* p = static_cast<const uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd_, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return fail(n < 0 ? errno : ENOSPC);
    p += n;
    size -= size_t(n);
  }
  return ContainerStatus::kOk;
}

ContainerStatus AtomicFile::writeAt(const void* data, size_t size, uint64_t offset) {
  if (fd_ < 0) return fail(EBADF);
  if (error_) return ContainerStatus::kIoError;
  const auto* p = static_cast<const uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::pwrite(fd_, p, size, off_t(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return fail(n < 0 ? errno : ENOSPC);
    p += n;
    size -= size_t(n);
    offset += uint64_t(n);
  }
  return ContainerStatus::kOk;
}

ContainerStatus AtomicFile::commit() {
  if (fd_ < 0 || committed_) return fail(EBADF);
  if (error_) {
    abort();
    return ContainerStatus::kIoError;
  }
  if (::fsync(fd_) != 0) fail(errno);
  bool placed = false;
  if (!error_ && tmp_path_.empty()) {
    // Anonymous file: link it straight to the path, or beside it and rename over an existing file.
    const std::string proc = "/proc/self/fd/" + std::to_string(fd_);
    if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, path_.c_str(), AT_SYMLINK_FOLLOW) == 0) {
      placed = true;
    } else if (errno == EEXIST) {
      for (int attempt = 0; attempt < 16 && !placed && !error_; ++attempt) {
        const std::string sibling = randomSibling(path_);
        if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, sibling.c_str(), AT_SYMLINK_FOLLOW) != 0) {
          if (errno != EEXIST) fail(errno);
          continue;
        }
        if (std::rename(sibling.c_str(), path_.c_str()) != 0) {
          fail(errno);
          ::unlink(sibling.c_str());
        } else {
          placed = true;
        }
      }
      if (!placed) fail(EEXIST);
    } else {
      fail(errno);
    }
  }
  if (::close(fd_) != 0) fail(errno);
  fd_ = -1;
  if (!error_ && !tmp_path_.empty()) {
    if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0) {
      fail(errno);
    } else {
      placed = true;
      tmp_path_.clear();
    }
  }
  if (error_) {
    // A link that succeeded before a failed close would leave a file that may be incomplete.
    if (placed && tmp_path_.empty()) ::unlink(path_.c_str());
    abort();
    return ContainerStatus::kIoError;
  }
  committed_ = true;
  syncDirectory(path_);
  return ContainerStatus::kOk;
}

void AtomicFile::abort() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!tmp_path_.empty()) {
    ::unlink(tmp_path_.c_str());
    tmp_path_.clear();
  }
}

std::string AtomicFile::errorMessage() const {
  return path_ + ": " + (error_ ? std::strerror(error_) : "cannot write");
}

ContainerStatus writeFileAtomically(const std::string& path, const void* data, size_t size,
                                    std::string* error_message) {
  AtomicFile file;
  ContainerStatus status = file.open(path);
  if (status == ContainerStatus::kOk) status = file.write(data, size);
  if (status == ContainerStatus::kOk) status = file.commit();
  if (status != ContainerStatus::kOk) {
    file.abort();
    if (error_message) *error_message = file.errorMessage();
  }
  return status;
}

}  // namespace glintbake::format
