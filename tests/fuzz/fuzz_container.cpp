// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: the container validator and reader on arbitrary bytes. Calls the same
// validate() as `glintinfo validate`, then the reader path a runtime uses (open, read every
// section). Any crash, sanitizer report, or leak is a bug.
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>

#include "reseal.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace {

using namespace glintbake::format;
using glintbake::fuzz::reseal;

void check(const uint8_t* data, size_t size) {
  // A small cap keeps each run fast; the checks are the same as with the default.
  ValidateOptions validate_options;
  validate_options.max_raw_section_size = uint64_t(16) << 20;
  const ValidationReport report = validate(data, size, validate_options);
  // A report without errors must mean the reader accepts the file and reads every known section.
  ReaderOptions reader_options;
  reader_options.max_raw_section_size = validate_options.max_raw_section_size;
  Reader reader;
  const ContainerStatus status = reader.openMemory(data, size, reader_options);
  if (report.valid() && status != ContainerStatus::kOk) __builtin_trap();
  if (status != ContainerStatus::kOk) return;
  std::vector<uint8_t> out;
  for (size_t i = 0; i < reader.sections().size(); ++i) {
    const ContainerStatus read = reader.readSection(i, &out);
    const uint32_t codec = reader.sections()[i].codec;
    const bool known = codec == uint32_t(Codec::kRaw) || codec == uint32_t(Codec::kZstd);
    if (report.valid() && known && read != ContainerStatus::kOk) __builtin_trap();
    if (read == ContainerStatus::kOk && out.size() != reader.sections()[i].raw_size) __builtin_trap();
  }
  std::string json;
  (void)reader.readMetadata(&json);
  (void)reader.verifyFileChecksum();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check(data, size);
  const std::vector<uint8_t> resealed = reseal(data, size);
  check(resealed.data(), resealed.size());
  return 0;
}
