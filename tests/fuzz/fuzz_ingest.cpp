// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: normal-map ingest (loadNormalMap) on arbitrary bytes, through every image
// reader OpenImageIO has (the file has no extension, so the reader is chosen by its content). The
// bytes are written to a private temporary file, since ingest reads files by path. Any crash,
// sanitizer report or leak in glintbake's code is a bug; a map that loads must hold unit normals
// of the upper hemisphere and no more texels than the size limit.
#include <glintbake/bake/io/normal_map.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace {

std::string scratchPath() {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir && *dir ? dir : "/tmp") + "/fuzz_ingest-" + std::to_string(::getpid());
}

bool writeAll(const std::string& path, const uint8_t* data, size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const bool ok = std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

void check(const std::string& path, const glintbake::bake::IngestOptions& options) {
  glintbake::bake::IngestReport report;
  const auto map = glintbake::bake::loadNormalMap(path, options, &report);
  if (!map.ok()) {
    if (map.error().message.find('\n') != std::string::npos) __builtin_trap();  // errors are one line
    return;
  }
  const glintbake::bake::NormalMap& m = map.value();
  if (m.width <= 0 || m.height <= 0 || m.width > options.max_size || m.height > options.max_size) __builtin_trap();
  if (m.normals.size() != size_t(m.width) * size_t(m.height) * 3) __builtin_trap();
  for (size_t i = 0; i < m.normals.size(); i += 3) {
    const float* n = &m.normals[i];
    const double length = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    if (!(std::fabs(length - 1.0) < 1e-3) || !(n[2] >= 0.0f)) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = scratchPath();
  if (!writeAll(path, data, size)) return 0;
  glintbake::bake::IngestOptions options;
  options.max_size = 512;  // keeps every run small; the checks are the same as with the default
  options.fix_nonfinite = true;
  check(path, options);
  options.height = true;  // the same bytes as a height field
  options.fix_nonfinite = false;
  check(path, options);
  std::remove(path.c_str());
  return 0;
}
