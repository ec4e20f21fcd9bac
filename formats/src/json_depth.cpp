// SPDX-License-Identifier: Apache-2.0
// jsonNestingDepth: one scan over the text, skipping strings and their escapes.
#include <glintbake/format/json_depth.h>

#include <algorithm>

namespace glintbake::format {

size_t jsonNestingDepth(const char* text, size_t size) {
  size_t depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

}  // namespace glintbake::format
