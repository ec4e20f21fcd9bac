// libFuzzer target: the container validator and reader on arbitrary bytes. Calls the same
// validate() as `glintinfo validate`, then the reader path a runtime uses (open, read every
// section). Any crash, sanitizer report, or leak is a bug.
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace {

using namespace glintbake::format;

uint64_t load64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
void store64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = uint8_t(v >> (8 * i));
}

// Recomputes the index, file and header checksums (SPEC.md 2.1) so that mutations reach the
// checks behind them instead of stopping at a checksum mismatch.
std::vector<uint8_t> reseal(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  if (size < kHeaderSize) return bytes;
  uint8_t* h = bytes.data();
  const uint64_t index_offset = load64(h + 32), index_size = load64(h + 40);
  if (index_offset <= size && index_size <= size - index_offset) {
    store64(h + 64, hash64(h + index_offset, size_t(index_size)));
  }
  store64(h + 56, hash64(h + kHeaderSize, size - kHeaderSize));
  store64(h + 72, 0);
  store64(h + 72, hash64(h, kHeaderSize));
  return bytes;
}

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
