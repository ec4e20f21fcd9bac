// SPDX-License-Identifier: Apache-2.0
// The normal-map ingest options shared by every tool that reads a normal map, their canonical JSON
// form, and the loader that maps library errors to exit codes.
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/cli/pyramid_options.h>
#include <glintbake/cli/stdin_input.h>

#include <cstdio>
#include <map>
#include <string>

namespace glintbake::cli {
namespace {

// Four significant digits, in exponent form when large or small ("1.732", "2e+30"): a report's
// figure, not a value to parse back.
std::string shortNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

}  // namespace

void addIngestOptions(CLI::App& app, bake::IngestOptions& options) {
  static const std::map<std::string, bake::Encoding> kEncodings = {
      {"auto", bake::Encoding::kAuto}, {"unorm", bake::Encoding::kUnorm}, {"snorm", bake::Encoding::kSnorm}};
  static const std::map<std::string, bake::Wrap> kWraps = {{"repeat", bake::Wrap::kRepeat},
                                                           {"clamp", bake::Wrap::kClamp}};
  const std::string group = "Normal-map input";
  app.add_option("--encoding", options.encoding,
                 "How stored values map to normals: auto (float files with negative values are signed, "
                 "everything else is (n+1)/2), unorm ((n+1)/2), snorm (values are n)")
      ->transform(CLI::CheckedTransformer(kEncodings).description(""))
      ->type_name("auto|unorm|snorm")
      ->default_str(bake::encodingString(options.encoding))
      ->group(group);
  app.add_flag("--flip-green", options.flip_green, "Negate n_y (DirectX maps, green down)")->group(group);
  app.add_flag("--height", options.height,
               "The input is a height field (first channel); normals by central differences")
      ->group(group);
  app.add_option("--height-scale", options.height_scale, "Height-field scale K: slope = K * dh/dtexel (> 0)")
      ->check(CLI::PositiveNumber)
      ->group(group);
  app.add_option("--wrap", options.wrap, "How the map continues beyond its edges: repeat or clamp")
      ->transform(CLI::CheckedTransformer(kWraps).description(""))
      ->type_name("repeat|clamp")
      ->default_str(bake::wrapString(options.wrap))
      ->group(group);
  app.add_option("--part", options.part, "Part (subimage) of a multi-part file to read (>= 0)")
      ->check(CLI::NonNegativeNumber)
      ->group(group);
  app.add_flag("--fix-nonfinite", options.fix_nonfinite, "Replace NaN/Inf texels by (0,0,1) instead of failing")
      ->group(group);
  app.add_option("--max-size", options.max_size, "Largest accepted width or height, in texels (1..1048576)")
      ->check(CLI::Range(1, 1 << 20))
      ->group(group);
}

Json ingestOptionsJson(const bake::IngestOptions& options) {
  Json j;
  j["encoding"] = bake::encodingString(options.encoding);
  j["flip_green"] = options.flip_green;
  j["height"] = options.height;
  j["height_scale"] = options.height_scale;
  j["wrap"] = bake::wrapString(options.wrap);
  j["part"] = options.part;
  j["fix_nonfinite"] = options.fix_nonfinite;
  return j;
}

Json ingestReportJson(const bake::IngestReport& report) {
  Json j;
  j["file_format"] = report.file_format;
  j["pixel_type"] = report.pixel_type;
  j["channels"] = report.channels_in;
  j["encoding"] = bake::encodingString(report.encoding_used);
  j["texels"] = report.texels;
  j["far_from_unit"] = report.far_from_unit;
  j["nz_nonpositive"] = report.nz_nonpositive;
  j["nonfinite"] = report.nonfinite;
  j["mean_length"] = report.mean_length;
  j["hash"] = report.content_hash;
  return j;
}

bake::NormalMap loadNormalMapForTool(Tool& tool, const std::string& path, const bake::IngestOptions& options,
                                     bake::IngestReport* report) {
  bake::IngestReport local;
  bake::IngestReport* r = report != nullptr ? report : &local;
  const std::string file = resolveInput(path);
  tool.addInput(file);
  bake::Result<bake::NormalMap> loaded = bake::loadNormalMap(file, options, r);
  if (!loaded) throw Error(exitCodeOf(loaded.error()), loaded.error().message);
  // Every tool needs neighbours to differentiate or filter: a 1x1 map is refused everywhere.
  requireBakeableMap(loaded.value(), path);

  const std::string name = baseName(path);
  if (r->nonfinite > 0) {
    tool.warning(name + ": replaced " + std::to_string(r->nonfinite) + " non-finite texel(s) by (0,0,1)");
  }
  if (r->nz_nonpositive > 0) {
    tool.warning(name + ": moved " + std::to_string(r->nz_nonpositive) + " texel(s) with n_z <= 0 onto the horizon");
  }
  if (r->far_from_unit > 0) {
    tool.warning(name + ": renormalised " + std::to_string(r->far_from_unit) + " of " + std::to_string(r->texels) +
                 " texel(s) far from unit length (mean length " + shortNumber(r->mean_length) + ")");
  }
  return std::move(loaded).value();
}

}  // namespace glintbake::cli
