// SPDX-License-Identifier: Apache-2.0
// glintref compare: error metrics of a render against a reference render, and an error heat map.
#include "commands.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/render/image_compare.h>
#include <glintbake/cli/exit_codes.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

namespace glintbake::glintref {
namespace {

// JSON has no infinity: identical images have psnr null.
cli::Json finiteOrNull(double x) { return std::isfinite(x) ? cli::Json(x) : cli::Json(nullptr); }

}  // namespace

CLI::App* addCompareCommand(CLI::App& app, CompareOptions& options) {
  CLI::App* cmd =
      app.add_subcommand("compare", "Compare an image with a reference: RMSE, relative MSE, PSNR, heat map");
  cmd->add_option("image", options.image, "Image to evaluate (EXR or any format OpenImageIO reads)")->required();
  cmd->add_option("reference", options.reference, "Reference image of the same size")->required();
  cmd->add_option("--heatmap", options.heatmap, "Write the per-pixel RMS error as a colour-ramp PNG");
  cmd->add_option("--heatmap-scale", options.heatmap_scale,
                  "Error mapped to the top of the ramp (0: 4 x the image RMSE)");
  cmd->add_option("--max-rel-mse", options.max_rel_mse,
                  "Exit with code 7 when the relative MSE exceeds this value (default: never)");
  return cmd;
}

void checkHeatmap(const std::string& heatmap, double heatmap_scale, const char* option) {
  if (!(heatmap_scale >= 0.0) || !std::isfinite(heatmap_scale)) {
    throw cli::Error(cli::kExitBadArguments, "--heatmap-scale must be >= 0");
  }
  if (heatmap.empty()) return;
  if (bake::imageExtension(heatmap) != "png") {
    throw cli::Error(cli::kExitBadArguments, std::string(option) + " " + heatmap + ": the heat map must be .png");
  }
  const std::filesystem::path parent = std::filesystem::path(heatmap).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw cli::Error(cli::kExitIo, "cannot write " + heatmap + ": no such directory");
  }
}

bake::render::RgbImage loadCompareImage(const std::string& path) {
  auto image = bake::render::loadRgbImage(path);
  if (!image) throw cli::Error(int(image.error().code), image.error().message);
  return std::move(image.value());
}

bake::render::CompareMetrics compareLoaded(cli::Tool& tool, const bake::render::RgbImage& image,
                                           const bake::render::RgbImage& reference, const std::string& heatmap,
                                           double heatmap_scale) {
  auto metrics = bake::render::compareImages(image, reference);
  if (!metrics) throw cli::Error(cli::kExitInvalidInput, metrics.error().message);
  if (!heatmap.empty()) {
    const std::vector<float> heat = bake::render::errorHeatMap(image, reference, heatmap_scale);
    bake::ImageWriteOptions wo;
    wo.png_bits = 8;
    cli::check(bake::writeImage(heatmap, image.width, image.height, 3, heat.data(), wo));
    tool.addOutput(heatmap);
  }
  return metrics.value();
}

cli::Json comparisonJson(const bake::render::CompareMetrics& m, const std::string& heatmap) {
  cli::Json doc;
  doc["rmse"] = m.rmse;
  doc["relative_mse"] = finiteOrNull(m.relative_mse);
  doc["psnr"] = finiteOrNull(m.psnr);
  doc["peak"] = m.peak;
  doc["max_abs_error"] = m.max_abs_error;
  doc["differing_values"] = m.differing_values;
  if (!heatmap.empty()) doc["heatmap"] = cli::baseName(heatmap);
  return doc;
}

int runCompare(cli::Tool& tool, CompareOptions& options) {
  checkHeatmap(options.heatmap, options.heatmap_scale, "--heatmap");
  if (!(options.max_rel_mse >= 0.0)) throw cli::Error(cli::kExitBadArguments, "--max-rel-mse must be >= 0");
  tool.addInput(options.image);
  tool.addInput(options.reference);
  const bake::render::RgbImage a = loadCompareImage(options.image), b = loadCompareImage(options.reference);
  const bake::render::CompareMetrics m = compareLoaded(tool, a, b, options.heatmap, options.heatmap_scale);
  const bool differs =
      options.max_rel_mse < std::numeric_limits<double>::infinity() && m.relative_mse > options.max_rel_mse;
  if (tool.common().json) {
    cli::Json doc;
    doc["tool"] = "glintref";
    doc["command"] = "compare";
    doc["image"] = cli::baseName(options.image);
    doc["reference"] = cli::baseName(options.reference);
    doc["width"] = b.width;
    doc["height"] = b.height;
    const cli::Json fields = comparisonJson(m, options.heatmap);
    for (const auto& [key, value] : fields.items()) doc[key] = value;
    doc["within_threshold"] = !differs;
    tool.printJson(doc);
  } else {
    std::ostringstream s;
    s << "rmse " << m.rmse << "  relative_mse " << m.relative_mse << "  psnr " << m.psnr << " dB";
    std::printf("%s\n", s.str().c_str());
  }
  return differs ? cli::kExitDifferences : cli::kExitOk;
}

}  // namespace glintbake::glintref
