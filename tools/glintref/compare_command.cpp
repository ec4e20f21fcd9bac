// SPDX-License-Identifier: Apache-2.0
// glintref compare: error metrics of a render against a reference render, and an error heat map.
#include "commands.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/render/image_compare.h>

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

cli::Json compareFiles(cli::Tool& tool, const std::string& image, const std::string& reference,
                       const std::string& heatmap, double heatmap_scale, double* relative_mse) {
  tool.addInput(image);
  tool.addInput(reference);
  auto a = bake::render::loadRgbImage(image);
  if (!a) throw cli::Error(int(a.error().code), a.error().message);
  auto b = bake::render::loadRgbImage(reference);
  if (!b) throw cli::Error(int(b.error().code), b.error().message);
  auto metrics = bake::render::compareImages(a.value(), b.value());
  if (!metrics) throw cli::Error(cli::kExitInvalidInput, metrics.error().message);
  const bake::render::CompareMetrics& m = metrics.value();
  if (!heatmap.empty()) {
    const std::vector<float> heat = bake::render::errorHeatMap(a.value(), b.value(), heatmap_scale);
    bake::ImageWriteOptions wo;
    wo.png_bits = 8;
    const bake::BakeStatus st = bake::writeImage(heatmap, a.value().width, a.value().height, 3, heat.data(), wo);
    if (!st) throw cli::Error(int(st.error().code), st.error().message);
    tool.addOutput(heatmap);
  }
  *relative_mse = m.relative_mse;
  cli::Json doc;
  doc["width"] = b.value().width;
  doc["height"] = b.value().height;
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
  double relative_mse = 0.0;
  const cli::Json fields =
      compareFiles(tool, options.image, options.reference, options.heatmap, options.heatmap_scale, &relative_mse);
  const bool differs =
      options.max_rel_mse < std::numeric_limits<double>::infinity() && relative_mse > options.max_rel_mse;
  if (tool.common().json) {
    cli::Json doc;
    doc["tool"] = "glintref";
    doc["command"] = "compare";
    doc["image"] = cli::baseName(options.image);
    doc["reference"] = cli::baseName(options.reference);
    for (const auto& [key, value] : fields.items()) doc[key] = value;
    doc["within_threshold"] = !differs;
    tool.printJson(doc);
  } else {
    std::ostringstream s;
    s << "rmse " << fields["rmse"].get<double>() << "  relative_mse " << relative_mse << "  psnr "
      << (fields["psnr"].is_null() ? std::numeric_limits<double>::infinity() : fields["psnr"].get<double>()) << " dB";
    std::printf("%s\n", s.str().c_str());
  }
  return differs ? cli::kExitDifferences : cli::kExitOk;
}

}  // namespace glintbake::glintref
