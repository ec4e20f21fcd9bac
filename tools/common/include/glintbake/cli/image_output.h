// SPDX-License-Identifier: Apache-2.0
// A PNG preview written beside a tool's main image output.
#pragma once

#include <glintbake/cli/tool.h>

#include <string>

namespace glintbake::cli {

// Writes the width x height single-channel `pixels` to `preview` (an 8-bit PNG) and registers it
// as an output. When the write fails, the main output already written (`output`) is removed, so
// that a failed run leaves nothing behind, and the write's error is thrown.
void writePreviewBeside(Tool& tool, const std::string& preview, const std::string& output, int width, int height,
                        const float* pixels);

}  // namespace glintbake::cli
