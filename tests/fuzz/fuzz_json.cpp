// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: the JSON inputs on arbitrary text, as the tools meet them: container metadata
// through validateMetadata() (what `glintinfo validate` runs), and a glintquery batch line through
// the same guards the batch command applies before parsing (NUL bytes, nesting depth), then
// nlohmann-json's parser, a dump with invalid UTF-8 replaced, and destruction. A stack overflow,
// crash or sanitizer report is a bug.
#include <glintbake/format/json_depth.h>
#include <glintbake/format/validate.h>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace glintbake::format;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<ValidationMessage> messages;
  validateMetadata(text, AssetKind::kNdfPyramid, &messages);
  if (text.find('\0') == std::string::npos && jsonNestingDepth(text) <= size_t(kMaxJsonDepth)) {
    const nlohmann::ordered_json doc = nlohmann::ordered_json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (!doc.is_discarded()) (void)doc.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  }
  return 0;
}
