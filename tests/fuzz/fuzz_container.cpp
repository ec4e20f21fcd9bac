// libFuzzer target: the container validator and reader on arbitrary bytes. Calls the same
// validate() as `glintinfo validate`, then the reader path a runtime uses (open, read every
// section). Any crash, sanitizer report, or leak is a bug.
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>

#include <cstddef>
#include <cstdint>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace glintbake::format;
  // A small cap keeps each run fast; the checks are the same as with the default.
  ValidateOptions validate_options;
  validate_options.max_raw_section_size = uint64_t(16) << 20;
  const ValidationReport report = validate(data, size, validate_options);
  // A report without errors must mean the reader accepts the file and reads every known section.
  ReaderOptions reader_options;
  reader_options.max_raw_section_size = validate_options.max_raw_section_size;
  Reader reader;
  const Status status = reader.openMemory(data, size, reader_options);
  if (report.valid() && status != Status::kOk) __builtin_trap();
  if (status != Status::kOk) return 0;
  std::vector<uint8_t> out;
  for (size_t i = 0; i < reader.sections().size(); ++i) {
    const Status read = reader.readSection(i, &out);
    const uint32_t codec = reader.sections()[i].codec;
    const bool known = codec == uint32_t(Codec::kRaw) || codec == uint32_t(Codec::kZstd);
    if (report.valid() && known && read != Status::kOk) __builtin_trap();
    if (read == Status::kOk && out.size() != reader.sections()[i].raw_size) __builtin_trap();
  }
  std::string json;
  (void)reader.readMetadata(&json);
  (void)reader.verifyFileChecksum();
  return 0;
}
