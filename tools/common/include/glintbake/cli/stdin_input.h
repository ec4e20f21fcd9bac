// SPDX-License-Identifier: Apache-2.0
// '-' as an input file: standard input, buffered once per process into an anonymous temporary file
// so that the readers (which hash an input before opening it, and seek) see an ordinary file.
#pragma once

#include <string>

namespace glintbake::cli {

// Inputs read from standard input are refused above this size (the buffer lives on disk, but the
// readers' own limits apply after it).
constexpr unsigned long long kMaxStdinBytes = 4ull << 30;

// The path to open for an input argument: `path` itself, or for "-" the buffered standard input
// (read on the first call; a second "-" input is kExitBadArguments, an empty or oversized stream
// kExitIo / kExitInvalidInput).
std::string resolveInput(const std::string& path);
// The path "-" resolved to, or empty when standard input was not read.
const std::string& stdinInputPath();
// `text` with the buffered standard input's path replaced by "standard input" (error messages).
std::string nameStdin(std::string text);

}  // namespace glintbake::cli
