// SPDX-License-Identifier: Apache-2.0
// glintinfo export: writes one layer of an image-like section as an EXR/PNG/... image.
#include <glintbake/cli/exit_codes.h>
#include "commands.h"
#include "container_access.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/format/validate.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>

namespace glintbake::glintinfo {
namespace {

bool parseUnsigned64(const std::string& text, uint64_t* value) {
  if (text.empty() || text.size() > 20) return false;
  uint64_t v = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    const uint64_t digit = uint64_t(c - '0');
    if (v > (UINT64_MAX - digit) / 10) return false;
    v = v * 10 + digit;
  }
  *value = v;
  return true;
}

// SECTION is an index ("3") or "type:key" with the type by name or number.
size_t resolveSection(const format::Reader& reader, const std::string& spec) {
  const size_t colon = spec.find(':');
  if (colon == std::string::npos) {
    uint64_t index = 0;
    if (!parseUnsigned64(spec, &index)) {
      throw cli::Error(cli::kExitBadArguments, "section \"" + spec + "\" is neither an index nor type:key");
    }
    if (index >= reader.sections().size()) {
      throw cli::Error(cli::kExitBadArguments, "section index " + spec + " is out of range (the file has " +
                                                   std::to_string(reader.sections().size()) + " sections)");
    }
    return size_t(index);
  }
  uint32_t type = 0;
  uint64_t key = 0;
  if (!format::sectionTypeFromString(spec.substr(0, colon), &type) || !parseUnsigned64(spec.substr(colon + 1), &key)) {
    throw cli::Error(cli::kExitBadArguments, "section \"" + spec + "\" is not type:key (e.g. ndf-chunk:4294967296)");
  }
  const int index = reader.find(type, key);
  if (index < 0) throw cli::Error(cli::kExitBadArguments, "no section " + spec + " in the file");
  return size_t(index);
}

std::string lowerExtension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace

CLI::App* addExportCommand(CLI::App& app, ExportOptions& options) {
  CLI::App* cmd = app.add_subcommand("export", "Write one layer of an image-like section as an image file");
  cmd->add_option("file", options.file, "Container file (.gbk)")->required();
  cmd->add_option("section", options.section, "Section index, or type:key (e.g. ndf-chunk:4294967296, 256:0)")
      ->required();
  cmd->add_option("--layer", options.layer, "Layer to export (0-based)");
  cmd->add_option("--channel", options.channel, "Export only this channel (0-based); default: all channels")
      ->check(CLI::Range(-1, 1 << 20));
  cmd->add_option("-o,--output", options.output, "Output image (.exr keeps float values; .png is normalised)")
      ->required();
  cmd->add_option("--scale", options.scale,
                  "Integer formats only: divide values by this before quantising ('auto' = the largest value)");
  cmd->footer("NDF images are exported as stored: s_x = -1 at the left, s_y = +1 at the top (SPEC.md, Coordinates).");
  return cmd;
}

int runExport(cli::Tool& tool, const ExportOptions& options) {
  const std::string ext = lowerExtension(options.output);
  const bool float_format = ext == "exr" || ext == "hdr" || ext == "pfm";
  const bool integer_format = ext == "png" || ext == "tif" || ext == "tiff" || ext == "ppm" || ext == "pgm";
  if (!float_format && !integer_format) {
    throw cli::Error(cli::kExitBadArguments, "output " + options.output + ": unsupported extension (use .exr or .png)");
  }
  double scale = 0.0;  // 0: auto
  if (options.scale != "auto") {
    char* end = nullptr;
    scale = std::strtod(options.scale.c_str(), &end);
    if (options.scale.empty() || *end != '\0' || !(scale > 0.0) || !std::isfinite(scale)) {
      throw cli::Error(cli::kExitBadArguments, "--scale must be 'auto' or a positive number, not " + options.scale);
    }
  }

  tool.addInput(options.file);
  const auto reader = openContainer(options.file);
  const size_t index = resolveSection(*reader, options.section);
  const format::SectionInfo& info = reader->sections()[index];
  const auto bytes = readSectionOrThrow(*reader, options.file, index);
  format::ImageSectionHeader header;
  if (!format::parseImageSection(bytes.data(), bytes.size(), &header)) {
    throw cli::Error(cli::kExitInvalidInput, options.file + ": section " + std::to_string(index) +
                                                 " is not an image section (no consistent GIMG header)");
  }
  if (options.layer >= header.layers) {
    throw cli::Error(cli::kExitBadArguments, "--layer " + std::to_string(options.layer) + " is out of range (" +
                                                 std::to_string(header.layers) + " layers)");
  }
  if (options.channel >= int64_t(header.channels)) {
    throw cli::Error(cli::kExitBadArguments, "--channel " + std::to_string(options.channel) + " is out of range (" +
                                                 std::to_string(header.channels) + " channels)");
  }
  const int out_channels = options.channel >= 0 ? 1 : int(header.channels);
  if (out_channels > 4) {
    throw cli::Error(cli::kExitBadArguments,
                     "the section has " + std::to_string(header.channels) + " channels; choose one with --channel");
  }
  if (header.width > uint32_t(std::numeric_limits<int>::max()) ||
      header.height > uint32_t(std::numeric_limits<int>::max())) {
    throw cli::Error(cli::kExitUnsupported, "image too large to export");
  }

  const size_t pixels = size_t(header.width) * header.height;
  const size_t layer_values = pixels * header.channels;
  const uint8_t* layer = bytes.data() + sizeof(format::ImageSectionHeader) + size_t(options.layer) * layer_values * 4;
  std::vector<float> out(pixels * size_t(out_channels));
  for (size_t p = 0; p < pixels; ++p) {
    for (int c = 0; c < out_channels; ++c) {
      const size_t src_channel = options.channel >= 0 ? size_t(options.channel) : size_t(c);
      std::memcpy(&out[p * size_t(out_channels) + size_t(c)], layer + (p * header.channels + src_channel) * 4, 4);
    }
  }

  double applied_scale = 1.0;
  if (integer_format) {
    if (scale == 0.0) {
      float max_value = 0.0f;
      for (float v : out) {
        if (std::isfinite(v)) max_value = std::max(max_value, v);
      }
      scale = max_value > 0.0f ? double(max_value) : 1.0;
    }
    applied_scale = scale;
    const float inv = float(1.0 / scale);
    for (float& v : out) v = std::isfinite(v) ? v * inv : 0.0f;
  }

  const bake::BakeStatus status =
      bake::writeImage(options.output, int(header.width), int(header.height), out_channels, out.data());
  cli::check(status);
  tool.addOutput(options.output);

  if (tool.common().json) {
    tool.printJson({{"file", cli::baseName(options.file)},
                    {"section", {{"index", index}, {"type", info.type}, {"key", info.key}}},
                    {"layer", options.layer},
                    {"channel", options.channel},
                    {"width", header.width},
                    {"height", header.height},
                    {"channels", out_channels},
                    {"scale", applied_scale},
                    {"output", cli::baseName(options.output)}});
  } else {
    tool.info("wrote " + options.output + " (" + std::to_string(header.width) + " x " + std::to_string(header.height) +
              ", " + std::to_string(out_channels) + " channels" +
              (integer_format ? ", divided by " + std::to_string(applied_scale) : std::string()) + ")");
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintinfo
