// SPDX-License-Identifier: Apache-2.0
// glintref image: the bin-averaged NDF image of a footprint (each bin the exact average of D over
// the bin), written as a 1-channel float EXR or, for viewing, a PNG normalised by its maximum.
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/image_output.h>
#include "commands.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/reference/pndf.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace glintbake::glintref {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace

CLI::App* addImageCommand(CLI::App& app, ImageOptions& options) {
  CLI::App* cmd =
      app.add_subcommand("image", "Write the bin-averaged NDF image of a footprint (.exr, or .png for viewing)");
  addQueryOptions(*cmd, options.query);
  cmd->add_option("--res", options.res, "Bins per side of the image over s in [-1,1]^2 (1..4096)");
  cmd->add_option("-o,--output", options.output, "Output image: .exr (float densities) or .png (scaled by the maximum)")
      ->required();
  cmd->add_option("--preview", options.preview,
                  "Also write the image as a .png scaled by its maximum (one evaluation for both)");
  return cmd;
}

int runImage(cli::Tool& tool, ImageOptions& options) {
  if (options.res < 1 || options.res > 4096) {
    throw cli::Error(cli::kExitBadArguments, "--res must be in 1..4096, got " + std::to_string(options.res));
  }
  const std::string ext = lowerExtension(options.output);
  if (ext != ".exr" && ext != ".png") {
    throw cli::Error(cli::kExitBadArguments, "-o " + options.output + ": the image must be .exr or .png");
  }
  if (!options.preview.empty() && lowerExtension(options.preview) != ".png") {
    throw cli::Error(cli::kExitBadArguments, "--preview " + options.preview + ": the preview must be .png");
  }
  for (const std::string& out : {options.output, options.preview}) {
    const std::filesystem::path parent = std::filesystem::path(out).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw cli::Error(cli::kExitIo, "cannot write " + out + ": no such directory");
    }
  }
  const Query query = loadQuery(tool, options.query);

  const int res = options.res;
  const size_t lobes = reference::footprintLobes(query.flakes, query.footprint, query.sigma_r).size();
  const std::vector<double> image = reference::binAveragedImage(query.flakes, query.footprint, query.sigma_r, res);

  double sum = 0.0, max_value = 0.0;
  for (double v : image) {
    sum += v;
    max_value = std::max(max_value, v);
  }
  const double bin_area = (2.0 / res) * (2.0 / res);
  const bool png = ext == ".png";
  const double scale = (png && max_value > 0.0) ? 1.0 / max_value : 1.0;
  std::vector<float> pixels(image.size());
  for (size_t k = 0; k < image.size(); ++k) pixels[k] = float(image[k] * scale);

  const bake::BakeStatus written = bake::writeImage(options.output, res, res, 1, pixels.data());
  cli::check(written);
  tool.addOutput(options.output);
  const double preview_scale = max_value > 0.0 ? 1.0 / max_value : 1.0;
  if (!options.preview.empty()) {
    for (size_t k = 0; k < image.size(); ++k) pixels[k] = float(image[k] * preview_scale);
    cli::writePreviewBeside(tool, options.preview, options.output, res, res, pixels.data());
  }

  if (tool.common().json) {
    cli::Json doc;
    doc["tool"] = "glintref";
    doc["command"] = "image";
    doc.update(queryJson(options.query, query, lobes));
    doc["res"] = res;
    doc["output"] = {{"name", cli::baseName(options.output)}, {"format", png ? "png" : "exr"}, {"scale", scale}};
    if (!options.preview.empty()) doc["preview"] = {{"name", cli::baseName(options.preview)}, {"scale", preview_scale}};
    doc["integral"] = sum * bin_area;
    doc["max"] = max_value;
    tool.printJson(doc);
  } else {
    tool.info("wrote " + options.output + " (" + std::to_string(res) + "x" + std::to_string(res) + ", integral " +
              std::to_string(sum * bin_area) + ")");
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintref
