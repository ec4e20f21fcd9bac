// SPDX-License-Identifier: Apache-2.0
// A temporary directory private to this test process. CTest runs the tests of one program as
// separate processes in parallel, so fixed file names under ::testing::TempDir() would collide.
#pragma once

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace glintbake::testing {

// ::testing::TempDir()/glintbake-<pid>/ (created on first use, removed with its contents when the
// process exits), with a trailing slash.
inline const std::string& processTempDir() {
  struct Dir {
    std::string path;
    Dir() {
      std::string base = ::testing::TempDir();
      if (base.empty() || base.back() != '/') base += '/';
      path = base + "glintbake-" + std::to_string(::getpid()) + "/";
      ::mkdir(path.c_str(), 0700);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

}  // namespace glintbake::testing
