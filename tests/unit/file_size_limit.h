// SPDX-License-Identifier: Apache-2.0
// Test helper: lowers the soft file-size limit (RLIMIT_FSIZE) for a scope with SIGXFSZ ignored, so
// writes past the limit fail with EFBIG as they do in a tool under `ulimit -f`.
#pragma once

#include <csignal>

#include <sys/resource.h>

namespace glintbake::test {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limited = saved_;
    limited.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limited);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, previous_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  void (*previous_handler_)(int) = SIG_DFL;
};

}  // namespace glintbake::test
