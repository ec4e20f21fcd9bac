// SPDX-License-Identifier: Apache-2.0
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/stdin_input.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>

namespace glintbake::cli {
namespace {

std::mutex g_stdin_mutex;
std::string g_stdin_path;  // "/dev/fd/N" once standard input is buffered
bool g_stdin_used = false;

}  // namespace

std::string resolveInput(const std::string& path) {
  if (path != "-") return path;
  std::lock_guard<std::mutex> lock(g_stdin_mutex);
  if (g_stdin_used) throw Error(kExitBadArguments, "standard input ('-') can be given to one input only");
  g_stdin_used = true;
  // An unlinked temporary file: nothing is left behind whatever happens to the process. It stays
  // open (and readable as /dev/fd/N) until the process ends.
  std::FILE* buffer = std::tmpfile();
  if (buffer == nullptr) throw Error(kExitIo, std::string("cannot buffer standard input: ") + std::strerror(errno));
  char chunk[1 << 16];
  unsigned long long total = 0;
  for (;;) {
    const size_t n = std::fread(chunk, 1, sizeof chunk, stdin);
    if (n == 0) break;
    total += n;
    if (total > kMaxStdinBytes) throw Error(kExitInvalidInput, "standard input is larger than 4 GiB");
    if (std::fwrite(chunk, 1, n, buffer) != n)
      throw Error(kExitIo, std::string("cannot buffer standard input: ") + std::strerror(errno));
  }
  if (std::ferror(stdin)) throw Error(kExitIo, "cannot read standard input");
  if (total == 0) throw Error(kExitInvalidInput, "standard input is empty");
  if (std::fflush(buffer) != 0)
    throw Error(kExitIo, std::string("cannot buffer standard input: ") + std::strerror(errno));
  std::rewind(buffer);
  g_stdin_path = "/dev/fd/" + std::to_string(fileno(buffer));
  return g_stdin_path;
}

const std::string& stdinInputPath() { return g_stdin_path; }

std::string nameStdin(std::string text) {
  const std::string& path = stdinInputPath();
  if (path.empty()) return text;
  for (size_t at = text.find(path); at != std::string::npos; at = text.find(path, at)) {
    text.replace(at, path.size(), "standard input");
    at += 14;
  }
  return text;
}

}  // namespace glintbake::cli
