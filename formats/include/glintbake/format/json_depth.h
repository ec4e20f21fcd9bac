// SPDX-License-Identifier: Apache-2.0
// Nesting depth of untrusted JSON text, measured before it is parsed: every JSON input of glintbake
// (container metadata, scenes, batch query lines) is refused when nested deeper than
// kMaxJsonDepth (container.h), because parsing, printing and destroying a document recurse once
// per level.
#pragma once

#include <glintbake/format/container.h>

#include <cstddef>
#include <string>

namespace glintbake::format {

// Deepest nesting of arrays and objects in text, outside strings, found by one linear scan (no
// recursion, no allocation). Safe on any bytes, valid JSON or not.
size_t jsonNestingDepth(const char* text, size_t size);
inline size_t jsonNestingDepth(const std::string& text) { return jsonNestingDepth(text.data(), text.size()); }

}  // namespace glintbake::format
