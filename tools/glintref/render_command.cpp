// SPDX-License-Identifier: Apache-2.0
// glintref render: a small CPU renderer of one object under direct lighting, with the P-NDF from
// the reference evaluator, a baked asset through the runtime, or a smooth analytic BRDF
// (libbake/render; scene format: schemas/scene.schema.json).
#include "commands.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/render/image_compare.h>
#include <glintbake/bake/render/renderer.h>
#include <glintbake/bake/render/scene.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/reference/flakes.h>
#include <glintbake/runtime/ltc.h>
#include <glintbake/runtime/ndf_source.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

namespace glintbake::glintref {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The command-line checks that need no file: the NDF mode and the --image-size override (0 x 0 when
// not given).
bake::render::NdfMode checkRenderOptions(const RenderOptions& options, int* width, int* height) {
  bake::render::NdfMode mode = bake::render::NdfMode::kSmooth;
  bake::render::ndfModeFromString(options.ndf, &mode);
  if (options.spp < 1 || options.spp > 65536) {
    throw cli::Error(cli::kExitBadArguments, "--spp must be in 1..65536, got " + std::to_string(options.spp));
  }
  *width = *height = 0;
  if (!options.image_size.empty()) {
    double w = 0.0, h = 0.0;
    parsePair("--image-size", options.image_size, &w, &h);
    if (w < 1 || w > 8192 || h < 1 || h > 8192 || w != std::floor(w) || h != std::floor(h)) {
      throw cli::Error(cli::kExitBadArguments, "--image-size must be two integers W,H in 1..8192");
    }
    *width = int(w);
    *height = int(h);
  }
  if (!options.ltc.empty() && mode != bake::render::NdfMode::kSmooth) {
    throw cli::Error(cli::kExitBadArguments, "--ltc needs --ndf smooth (the table holds the smooth GGX BRDF)");
  }
  if (!(options.exposure > 0.0) || !std::isfinite(options.exposure)) {
    throw cli::Error(cli::kExitBadArguments, "--exposure must be positive");
  }
  if (!bake::isFloatImagePath(options.output) || bake::imageExtension(options.output) != "exr") {
    throw cli::Error(cli::kExitBadArguments, "-o " + options.output + ": the render must be written as .exr");
  }
  if (!options.preview.empty() && bake::imageExtension(options.preview) != "png") {
    throw cli::Error(cli::kExitBadArguments, "--preview " + options.preview + ": the preview must be .png");
  }
  if (options.compare.empty() && (!options.heatmap.empty() || options.heatmap_scale != 0.0)) {
    throw cli::Error(cli::kExitBadArguments, "--heatmap and --heatmap-scale need --compare");
  }
  checkHeatmap(options.heatmap, options.heatmap_scale, "--heatmap");
  std::error_code ec;
  if (!options.compare.empty() && std::filesystem::equivalent(options.compare, options.output, ec) && !ec) {
    throw cli::Error(cli::kExitBadArguments, "--compare " + options.compare + " is the render's own output (-o)");
  }
  for (const std::string& out : {options.output, options.preview}) {
    if (out.empty()) continue;
    const std::filesystem::path parent = std::filesystem::path(out).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw cli::Error(cli::kExitIo, "cannot write " + out + ": no such directory");
    }
  }
  return mode;
}

// The scene with the command line's overrides.
bake::render::Scene loadRenderScene(cli::Tool& tool, const RenderOptions& options, int width, int height) {
  if (options.scene == "-")
    throw cli::Error(cli::kExitBadArguments,
                     "a scene cannot be read from standard input ('-'): its relative paths need the scene's folder");
  tool.addInput(options.scene);
  bake::render::Scene scene = cli::unwrap(bake::render::loadScene(options.scene));
  if (!options.asset.empty()) scene.material.asset = options.asset;
  if (!options.normal_map.empty()) scene.material.normal_map = options.normal_map;
  if (width > 0) {
    scene.camera.width = width;
    scene.camera.height = height;
  }
  return scene;
}

// What the NDF mode reads: the map (for the reference's flakes, or only for its size when the scene
// does not state it), the asset, the LTC table. `inputs` points into this.
struct RenderSources {
  bake::render::NdfInputs inputs;
  std::optional<reference::FlakeSet> flakes;
  std::unique_ptr<runtime::NdfSource> asset;
  runtime::LtcTable ltc;
};

void loadMapInputs(cli::Tool& tool, const RenderOptions& options, bake::render::NdfMode mode,
                   const bake::render::Scene& scene, RenderSources* sources) {
  bake::render::NdfInputs& inputs = sources->inputs;
  const bool need_map =
      mode == bake::render::NdfMode::kReference ||
      (inputs.map_width == 0 && (mode == bake::render::NdfMode::kAsset || !scene.material.normal_map.empty()));
  if (!need_map) return;
  if (scene.material.normal_map.empty()) {
    throw cli::Error(cli::kExitBadArguments,
                     mode == bake::render::NdfMode::kReference
                         ? "--ndf reference needs material.normal_map (or --normal-map)"
                         : "--ndf asset needs material.map_size or a normal map for the map size");
  }
  bake::IngestReport report;
  const bake::NormalMap map = cli::loadNormalMapForTool(tool, scene.material.normal_map, options.ingest, &report);
  if (inputs.map_width == 0) {
    inputs.map_width = map.width;
    inputs.map_height = map.height;
  }
  if (mode == bake::render::NdfMode::kReference) {
    sources->flakes = reference::buildFlakes(map, scene.material.rate);
    inputs.flakes = &*sources->flakes;
  }
}

void loadRenderSources(cli::Tool& tool, const RenderOptions& options, bake::render::NdfMode mode,
                       const bake::render::Scene& scene, RenderSources* sources) {
  bake::render::NdfInputs& inputs = sources->inputs;
  inputs.map_width = scene.material.map_width;
  inputs.map_height = scene.material.map_height;
  loadMapInputs(tool, options, mode, scene, sources);
  if (mode == bake::render::NdfMode::kAsset) {
    if (scene.material.asset.empty()) {
      throw cli::Error(cli::kExitBadArguments, "--ndf asset needs material.asset (or --asset)");
    }
    tool.addInput(scene.material.asset);
    const runtime::RuntimeStatus st = runtime::openNdfAsset(scene.material.asset.c_str(), &sources->asset);
    if (st != runtime::RuntimeStatus::kOk) {
      throw cli::Error(cli::exitCodeOf(st),
                       "cannot open asset " + scene.material.asset + ": " + runtime::statusString(st));
    }
    inputs.asset = sources->asset.get();
  }
  if (mode == bake::render::NdfMode::kSmooth && inputs.map_width == 0) {
    inputs.map_width = inputs.map_height = 1;  // footprints are not used by the smooth BRDF
  }
  if (!options.ltc.empty()) {
    tool.addInput(options.ltc);
    const runtime::RuntimeStatus st = sources->ltc.open(options.ltc.c_str());
    if (st != runtime::RuntimeStatus::kOk) {
      throw cli::Error(cli::exitCodeOf(st), "cannot open LTC table " + options.ltc + ": " + runtime::statusString(st));
    }
  }
}

// One image file, written atomically.
void writeRenderImage(cli::Tool& tool, const std::string& path, int width, int height, const float* rgb, int png_bits) {
  bake::ImageWriteOptions wo;
  if (png_bits > 0) wo.png_bits = png_bits;
  cli::check(bake::writeImage(path, width, height, 3, rgb, wo));
  tool.addOutput(path);
}

// The render, then the preview.
void writeRenderOutputs(cli::Tool& tool, const RenderOptions& options, const bake::render::RenderedImage& image) {
  writeRenderImage(tool, options.output, image.width, image.height, image.rgb.data(), 0);
  if (!options.preview.empty()) {
    bake::render::RgbImage rgb{image.width, image.height, image.rgb};
    const std::vector<float> display = bake::render::tonemapSrgb(rgb, options.exposure);
    writeRenderImage(tool, options.preview, image.width, image.height, display.data(), 8);
  }
}

void printRenderSummary(cli::Tool& tool, const RenderOptions& options, bake::render::NdfMode mode,
                        const bake::render::NdfInputs& inputs, const bake::render::RenderedImage& image,
                        double load_seconds, double render_seconds, const bake::render::CompareMetrics* comparison) {
  if (tool.common().json) {
    cli::Json doc;
    doc["tool"] = "glintref";
    doc["command"] = "render";
    doc["scene"] = cli::baseName(options.scene);
    doc["ndf"] = bake::render::ndfModeString(mode);
    doc["env"] = options.env;
    doc["area"] = options.ltc.empty() ? "sample" : "ltc";
    doc["spp"] = options.spp;
    doc["seed"] = options.seed;
    doc["width"] = image.width;
    doc["height"] = image.height;
    doc["threads"] = tool.threadCount();
    doc["pixels_hit"] = image.stats.pixels_hit;
    doc["footprint_sigma_texels"] = {{"mean", image.stats.mean_sigma_texels}, {"max", image.stats.max_sigma_texels}};
    doc["mean_radiance"] = {image.stats.mean_radiance[0], image.stats.mean_radiance[1], image.stats.mean_radiance[2]};
    doc["map_size"] = {inputs.map_width, inputs.map_height};
    doc["time_seconds"] = {{"load", load_seconds}, {"render", render_seconds}};
    doc["output"] = cli::baseName(options.output);
    if (!options.preview.empty()) doc["preview"] = cli::baseName(options.preview);
    if (comparison) {
      doc["compare"] = comparisonJson(*comparison, options.heatmap);
      doc["compare"]["reference"] = cli::baseName(options.compare);
    }
    tool.printJson(doc);
  } else {
    tool.info("wrote " + options.output + " (" + std::to_string(image.width) + "x" + std::to_string(image.height) +
              ", --ndf " + options.ndf + ", " + std::to_string(render_seconds) + " s)");
    if (comparison) {
      std::ostringstream s;
      s << "against " << options.compare << ": rmse " << comparison->rmse << "  relative_mse "
        << comparison->relative_mse;
      tool.info(s.str());
    }
  }
}

}  // namespace

CLI::App* addRenderCommand(CLI::App& app, RenderOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a scene (schemas/scene.schema.json) with the reference P-NDF, a baked asset or a smooth BRDF");
  cmd->add_option("scene", options.scene, "Scene JSON file")->required();
  cmd->add_option("-o,--output", options.output, "Output image: float .exr (linear radiance)")->required();
  cmd->add_option("--ndf", options.ndf,
                  "Where D comes from: reference (exact P-NDF of the normal map, slow), asset (the baked asset "
                  "through the runtime) or smooth (analytic GGX/Beckmann of the base roughness)")
      ->check(CLI::IsMember({"reference", "asset", "smooth"}));
  cmd->add_option("--spp", options.spp, "Light and BRDF samples per pixel for area and environment lights (1..65536)");
  cmd->add_option("--seed", options.seed, "Seed of the per-pixel random streams");
  cmd->add_option("--env", options.env,
                  "SG environment shading with --ndf asset: prefilter (averaged NDF over the light's support) or "
                  "sample (MIS like the other modes)")
      ->check(CLI::IsMember({"prefilter", "sample"}));
  cmd->add_option(
      "--ltc", options.ltc,
      "Shade polygon lights with this GGX LTC table (ltcfit table) instead of sampling; needs --ndf smooth");
  cmd->add_option("--asset", options.asset, "Override the material's asset (any NDF asset kind)");
  cmd->add_option("--normal-map", options.normal_map, "Override the material's normal map");
  cmd->add_option("--image-size", options.image_size, "Override the camera's image size: W,H in pixels (1..8192)");
  cmd->add_option("--preview", options.preview, "Also write a tone-mapped sRGB PNG preview");
  cmd->add_option("--exposure", options.exposure, "Exposure multiplier of the preview (> 0)");
  cmd->add_option("--compare", options.compare,
                  "Also compare the written render with this reference image (the metrics of glintref compare, "
                  "under 'compare' in --json)");
  cmd->add_option("--heatmap", options.heatmap, "With --compare: write its per-pixel RMS error as a colour-ramp PNG");
  cmd->add_option("--heatmap-scale", options.heatmap_scale,
                  "With --heatmap: error mapped to the top of the ramp (0: 4 x the image RMSE)");
  cli::addIngestOptions(*cmd, options.ingest);
  return cmd;
}

int runRender(cli::Tool& tool, RenderOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  int width = 0, height = 0;
  const bake::render::NdfMode mode = checkRenderOptions(options, &width, &height);
  const bake::render::Scene scene = loadRenderScene(tool, options, width, height);
  // The reference is read and its size checked before the render, so that a bad one fails fast.
  bake::render::RgbImage reference;
  if (!options.compare.empty()) {
    tool.addInput(options.compare);
    reference = loadCompareImage(options.compare);
    if (reference.width != scene.camera.width || reference.height != scene.camera.height) {
      throw cli::Error(cli::kExitInvalidInput,
                       "--compare " + options.compare + " is " + std::to_string(reference.width) + "x" +
                           std::to_string(reference.height) + ", the render " + std::to_string(scene.camera.width) +
                           "x" + std::to_string(scene.camera.height));
    }
  }
  RenderSources sources;
  loadRenderSources(tool, options, mode, scene, &sources);
  const double load_seconds = secondsSince(t_start);

  bake::render::RenderOptions ro;
  ro.mode = mode;
  ro.env_method = options.env == "sample" ? bake::render::EnvMethod::kSample : bake::render::EnvMethod::kPrefilter;
  ro.spp = options.spp;
  ro.seed = options.seed;
  ro.ltc = options.ltc.empty() ? nullptr : &sources.ltc;
  const uint64_t pixels = uint64_t(scene.camera.width) * uint64_t(scene.camera.height);
  std::unique_ptr<cli::Progress> progress = tool.progress("render", pixels);
  ro.progress = [&](uint64_t n) { progress->advance(n); };

  const auto t_render = std::chrono::steady_clock::now();
  bake::Result<bake::render::RenderedImage> rendered = bake::render::renderScene(scene, sources.inputs, ro);
  const double render_seconds = secondsSince(t_render);
  progress->finish();
  const bake::render::RenderedImage image = cli::unwrap(std::move(rendered));
  writeRenderOutputs(tool, options, image);
  // The comparison reads the render back as written (the file's precision), so that its figures
  // are glintref compare's.
  bake::render::CompareMetrics comparison;
  if (!options.compare.empty()) {
    try {
      comparison =
          compareLoaded(tool, loadCompareImage(options.output), reference, options.heatmap, options.heatmap_scale);
    } catch (...) {
      // No partial output: the render and its preview go with a comparison that failed.
      for (const std::string& out : {options.output, options.preview, options.heatmap})
        if (!out.empty()) {
          std::error_code ignored;
          std::filesystem::remove(out, ignored);
        }
      throw;
    }
  }
  printRenderSummary(tool, options, mode, sources.inputs, image, load_seconds, render_seconds,
                     options.compare.empty() ? nullptr : &comparison);
  return cli::kExitOk;
}

}  // namespace glintbake::glintref
