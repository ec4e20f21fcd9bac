// ndfgen: bakes the multi-level footprint pyramid of NDF images of a normal map into an
// ndf-pyramid container (libbake/ndf/pyramid_builder.h; layout in formats/SPEC.md).
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/cli/pyramid_options.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>

#include <chrono>
#include <cmath>
#include <string>

namespace {

using glintbake::cli::Error;
using glintbake::cli::Json;
namespace bake = glintbake::bake;
namespace cli = glintbake::cli;
namespace format = glintbake::format;

Json levelJson(const bake::ndf::PyramidLevelReport& l, int region_size) {
  Json j;
  j["level"] = l.level;
  j["stride"] = {l.geometry.stride_x, l.geometry.stride_y};
  j["sigma"] = l.geometry.sigma;
  j["grid"] = {l.geometry.grid_width, l.geometry.grid_height};
  j["first_centre"] = {0.5 * l.geometry.stride_x, 0.5 * l.geometry.stride_y};
  j["region_size"] = region_size;
  j["regions"] = l.geometry.regions_x * l.geometry.regions_y;
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Tool tool("ndfgen", "Bakes the footprint pyramid of P-NDF images of a normal map (ndf-pyramid asset)");
  std::string input, output;
  bake::IngestOptions ingest;
  cli::PyramidCliOptions pyramid;
  const bake::ndf::PyramidOptions& opt = pyramid.options;
  int zstd_level = 3;
  CLI::App& app = tool.app();
  app.add_option("map", input, "Normal map (or height field with --height)")->required();
  app.add_option("-o,--output", output, "Output ndf-pyramid container (.gbk)")->required();
  cli::addPyramidOptions(app, pyramid, "Footprint centres per side of a streamed chunk (1..256)");
  app.add_option("--zstd-level", zstd_level, "zstd compression level of the chunks (1..19)")->capture_default_str();
  cli::addIngestOptions(app, ingest);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    const auto t0 = std::chrono::steady_clock::now();
    if (zstd_level < 1 || zstd_level > 19) throw Error(cli::kExitBadArguments, "--zstd-level must be in [1, 19]");
    cli::resolvePyramidOptions(pyramid);

    bake::IngestReport ingest_report;
    const bake::NormalMap map = cli::loadNormalMapForTool(t, input, ingest, &ingest_report);
    cli::requireBakeableMap(map, input);
    cli::checkMemoryBudget(pyramid, map, t.threadCount(), /*tensor=*/false);

    cli::ContainerOutput out(t, output, format::AssetKind::kNdfPyramid, zstd_level);

    bake::ndf::PyramidReport report;
    cli::LevelProgress progress(t);
    const bake::BakeStatus built = bake::ndf::buildNdfPyramid(map, opt, out.writer(), &report, progress.callback());
    progress.finish();
    cli::check(built);
    const bake::ndf::FlakesHandover handover = cli::defaultFlakesHandover(pyramid);
    const uint64_t flake_bytes = cli::writeFlakes(out.writer(), map, pyramid, handover);

    Json params = cli::pyramidOptionsJson(pyramid);
    params["zstd_level"] = zstd_level;
    params["ingest"] = cli::ingestOptionsJson(ingest);
    Json meta = out.makeMetadata(params);
    Json asset;
    asset["ndf_res"] = opt.splat.ndf_res;
    asset["sigma_r"] = opt.splat.sigma_r;
    asset["map_size"] = {map.width, map.height};
    asset["wrap"] = bake::wrapString(map.wrap);
    asset["rate"] = opt.rate;
    asset["centre_grid"] = "centre (i, j) of level l at ((i + 0.5) stride_x, (j + 0.5) stride_y) texels";
    asset["levels"] = Json::array();
    for (const auto& l : report.levels) asset["levels"].push_back(levelJson(l, opt.region_size));
    asset["stop_reason"] = report.stop_reason;
    if (report.next_level_mse >= 0) asset["converged_mse"] = report.next_level_mse;
    if (pyramid.flakes) asset["flakes"] = cli::flakesJson(handover, flake_bytes);
    meta["asset"] = asset;
    out.finish(meta);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    uint64_t raw = 0, stored = 0, images = 0;
    for (const auto& l : report.levels) {
      raw += l.raw_bytes;
      stored += l.stored_bytes;
      images += l.images;
    }
    if (t.common().json) {
      Json doc;
      doc["tool"] = "ndfgen";
      doc["input"] = cli::baseName(input);
      doc["output"] = cli::baseName(output);
      doc["map"] = {{"width", map.width}, {"height", map.height}, {"wrap", bake::wrapString(map.wrap)}};
      doc["ingest"] = cli::ingestReportJson(ingest_report);
      doc["parameters"] = params;
      Json levels = Json::array();
      for (const auto& l : report.levels) {
        Json j = levelJson(l, opt.region_size);
        j["images"] = l.images;
        j["raw_bytes"] = l.raw_bytes;
        j["stored_bytes"] = l.stored_bytes;
        j["seconds"] = l.seconds;
        j["mse_vs_previous"] = l.mse_vs_previous < 0 ? Json(nullptr) : Json(l.mse_vs_previous);
        levels.push_back(j);
      }
      doc["levels"] = levels;
      doc["stop_reason"] = report.stop_reason;
      doc["converged_mse"] = report.next_level_mse < 0 ? Json(nullptr) : Json(report.next_level_mse);
      doc["flakes"] = report.flakes;
      doc["flakes_section_bytes"] = flake_bytes;
      doc["images"] = images;
      doc["raw_bytes"] = raw;
      doc["file_bytes"] = out.bytesWritten();
      doc["seconds"] = seconds;
      t.printJson(doc);
    } else {
      t.info("wrote " + output + ": " + std::to_string(report.levels.size()) + " levels, " + std::to_string(images) +
             " images, " + std::to_string(out.bytesWritten()) + " bytes (" + std::to_string(raw) + " raw) in " +
             std::to_string(seconds) + " s");
    }
    return cli::kExitOk;
  });
}
