// SPDX-License-Identifier: Apache-2.0
#include <glintbake/cli/image_output.h>

#include <glintbake/bake/io/image_io.h>
#include <glintbake/cli/exit_codes.h>

#include <filesystem>
#include <system_error>

namespace glintbake::cli {

void writePreviewBeside(Tool& tool, const std::string& preview, const std::string& output, int width, int height,
                        const float* pixels) {
  const bake::BakeStatus st = bake::writeImage(preview, width, height, 1, pixels);
  if (!st) {
    std::error_code ignored;
    std::filesystem::remove(output, ignored);
    check(st);
  }
  tool.addOutput(preview);
}

}  // namespace glintbake::cli
