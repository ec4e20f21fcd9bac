// SPDX-License-Identifier: Apache-2.0
// glintquery image: the blended NDF image the runtime sees for one footprint, as an image file.
#include "commands.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/image_output.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <vector>

namespace glintbake::glintquery {

namespace rt = glintbake::runtime;
using cli::Error;
using cli::Json;

namespace {

// Densities are written as they are to float formats; integer formats get 1 / max unless --scale.
double imageScale(const std::string& output, double png_scale, double peak) {
  std::string ext =
      output.substr(output.find_last_of('.') == std::string::npos ? output.size() : output.find_last_of('.'));
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  const bool float_format = ext == ".exr" || ext == ".hdr" || ext == ".pfm";
  return png_scale > 0.0 ? png_scale : (float_format ? 1.0 : (peak > 0.0 ? 1.0 / peak : 1.0));
}

}  // namespace

CLI::App* addImageCommand(CLI::App& app, ImageOptions& options) {
  CLI::App* image = app.add_subcommand("image", "The blended NDF image the runtime sees (EXR: densities, PNG: scaled)");
  addFootprintOptions(image, options.footprint);
  image->add_option("-o,--output", options.output, "Output image (.exr, .png, ...)")->required();
  image->add_option("--scale", options.png_scale,
                    "Multiply densities by this before writing (default: 1 for float "
                    "formats, 1/max for integer formats)");
  image->add_option("--preview", options.preview,
                    "Also write the image as an 8-bit PNG, densities times --preview-scale (one evaluation for both)");
  image->add_option("--preview-scale", options.preview_scale, "Scale of the --preview PNG (default: 1/max)");
  return image;
}

int runImage(cli::Tool& tool, const ImageOptions& options) {
  double x, y;
  parsePair(options.footprint.at_text, "--at", &x, &y);
  const rt::Footprint fp = parseFootprint(options.footprint);
  if (!(options.png_scale >= 0.0) || !std::isfinite(options.png_scale))
    throw Error(cli::kExitBadArguments, "--scale must be >= 0");
  if (!(options.preview_scale >= 0.0) || !std::isfinite(options.preview_scale))
    throw Error(cli::kExitBadArguments, "--preview-scale must be >= 0");
  if (!options.preview.empty() && bake::imageExtension(options.preview) != "png")
    throw Error(cli::kExitBadArguments, "--preview " + options.preview + ": the preview must be .png");
  if (options.preview.empty() && options.preview_scale != 0.0)
    throw Error(cli::kExitBadArguments, "--preview-scale needs --preview");
  const Asset ndf = openAsset(tool, options.footprint.asset);
  const int res = ndf.source->resolution();
  std::vector<float> pixels(size_t(res) * size_t(res));
  checkQuery(ndf.source->image(fp, pixels.data(), pixels.size()), "image query");
  double mass = 0.0, peak = 0.0;
  for (float v : pixels) {
    mass += v;
    peak = std::max(peak, double(v));
  }
  mass *= 4.0 / (double(res) * res);
  const double scale = imageScale(options.output, options.png_scale, peak);
  const double preview_scale = options.preview_scale > 0.0 ? options.preview_scale : (peak > 0.0 ? 1.0 / peak : 1.0);
  std::vector<float> preview(options.preview.empty() ? 0 : pixels.size(), 0.0f);
  for (size_t k = 0; k < preview.size(); ++k) preview[k] = float(pixels[k] * preview_scale);
  if (scale != 1.0)
    for (float& v : pixels) v = float(v * scale);
  cli::check(bake::writeImage(options.output, res, res, 1, pixels.data()));
  tool.addOutput(options.output);
  if (!options.preview.empty())
    cli::writePreviewBeside(tool, options.preview, options.output, res, res, preview.data());
  if (tool.common().json) {
    Json doc;
    doc["tool"] = "glintquery";
    doc["op"] = "image";
    doc["asset"] = cli::baseName(options.footprint.asset);
    doc["kind"] = ndf.kind;
    doc["output"] = cli::baseName(options.output);
    doc["at"] = {x, y};
    doc["sigma"] = fp.sigma;
    doc["resolution"] = res;
    doc["mass"] = mass;
    doc["max"] = peak;
    doc["scale"] = scale;
    if (!options.preview.empty()) doc["preview"] = {{"name", cli::baseName(options.preview)}, {"scale", preview_scale}};
    tool.printJson(doc);
  } else {
    tool.info("wrote " + options.output + " (" + std::to_string(res) + "x" + std::to_string(res) + ", mass " +
              std::to_string(mass) + ")");
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintquery
