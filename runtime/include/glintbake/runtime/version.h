// SPDX-License-Identifier: Apache-2.0
// The version of the runtime library a program runs against (which may differ from the headers
// it was compiled with, glintbake/version.h, when the runtime is a shared library).
#pragma once

#include <glintbake/version.h>

namespace glintbake::runtime {

struct Version {
  int major = 0;
  int minor = 0;
  int patch = 0;
};

// The library's version, and as text "major.minor.patch". Thread-safe; the string is static.
Version version();
const char* versionString();

}  // namespace glintbake::runtime
