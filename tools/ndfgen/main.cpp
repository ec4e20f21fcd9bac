// SPDX-License-Identifier: Apache-2.0
// ndfgen: bakes the multi-level footprint pyramid of NDF images of a normal map into an
// ndf-pyramid container (libbake/ndf/pyramid_builder.h; layout in formats/SPEC.md). With
// --procedural glitter the images come from a procedural glitter surface instead of a map
// (libbake/glitter), and --glitter-asset writes the surface itself as a glitter asset.
#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/embed.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/glitter_options.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/cli/pyramid_options.h>
#include <glintbake/cli/shard_output.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/flakes.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

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

// ndfgen --procedural glitter: the pyramid of a glitter surface (or, with --glitter-asset, the
// surface itself).
cli::ExitCode bakeProcedural(cli::Tool& t, const cli::GlitterCliOptions& glitter, bool as_asset,
                             const cli::PyramidCliOptions& pyramid, const std::string& output, int zstd_level,
                             std::chrono::steady_clock::time_point t0) {
  const bake::ndf::PyramidOptions& opt = pyramid.options;
  const bake::glitter::GlitterParams gp = cli::resolveGlitterOptions(glitter, opt.splat.ndf_res);
  const bake::glitter::GlitterModel model(gp);
  Json params = cli::pyramidOptionsJson(pyramid);
  params["zstd_level"] = zstd_level;
  params["glitter"] = cli::glitterParamsJson(gp);
  Json asset;
  asset["glitter"] = cli::glitterParamsJson(gp);
  asset["integral_entries"] = model.integrals().size();
  bake::ndf::PyramidReport report;
  uint64_t images = 0;
  if (as_asset) {
    cli::ContainerOutput out(t, output, format::AssetKind::kGlitter, zstd_level);
    const format::GlitterTreeShape shape = bake::glitter::defaultGlitterShape(gp, opt.sigma0);
    cli::check(bake::glitter::writeGlitterSections(out.writer(), model, shape));
    asset["tree_shape"] = {{"area", shape.area}, {"cone", shape.cone}};
    Json meta = out.makeMetadata(params);
    meta["asset"] = asset;
    out.finish(meta);
    if (!t.common().json)
      t.info("wrote " + output + ": glitter asset, " + std::to_string(out.bytesWritten()) + " bytes");
  } else {
    cli::ContainerOutput out(t, output, format::AssetKind::kNdfPyramid, zstd_level);
    const bake::glitter::GlitterImageSource source(model, opt.splat.ndf_res, opt.sigma0);
    cli::LevelProgress progress(t);
    const bake::BakeStatus built =
        bake::ndf::buildNdfPyramid(source, opt, out.writer(), &report, progress.callback(), cli::cancelFlag());
    progress.finish();
    cli::check(built);
    asset["ndf_res"] = opt.splat.ndf_res;
    asset["map_size"] = {gp.map_width, gp.map_height};
    asset["wrap"] = "repeat";
    asset["centre_grid"] = "centre (i, j) of level l at ((i + 0.5) stride_x, (j + 0.5) stride_y) texels";
    asset["levels"] = Json::array();
    for (const auto& l : report.levels) {
      asset["levels"].push_back(levelJson(l, opt.region_size));
      images += l.images;
    }
    asset["stop_reason"] = report.stop_reason;
    Json meta = out.makeMetadata(params);
    meta["asset"] = asset;
    out.finish(meta);
    if (!t.common().json)
      t.info("wrote " + output + ": glitter pyramid, " + std::to_string(report.levels.size()) + " levels, " +
             std::to_string(images) + " images, " + std::to_string(out.bytesWritten()) + " bytes");
  }
  if (t.common().json) {
    Json doc;
    doc["tool"] = "ndfgen";
    doc["procedural"] = "glitter";
    doc["output"] = cli::baseName(output);
    doc["kind"] = as_asset ? "glitter" : "ndf-pyramid";
    doc["parameters"] = params;
    doc["levels"] = Json::array();
    for (const auto& l : report.levels) {
      Json j = levelJson(l, opt.region_size);
      j["images"] = l.images;
      j["seconds"] = l.seconds;
      doc["levels"].push_back(j);
    }
    doc["images"] = images;
    doc["integral_entries"] = model.integrals().size();
    doc["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t.printJson(doc);
  }
  return cli::kExitOk;
}

// ndfgen --shard I/N: the regions (and maybe the flakes section) the plan gives this shard, into a
// partial container that glintinfo merge joins with the other shards.
template <typename AssetMetadata>
cli::ExitCode bakeShard(cli::Tool& t, const bake::NormalMap& map, const cli::PyramidCliOptions& pyramid,
                        const bake::shard::ShardSpec& spec, const std::string& output, int zstd_level,
                        const bake::ndf::FlakesHandover& handover, const AssetMetadata& assetMetadata,
                        std::chrono::steady_clock::time_point t0) {
  const cli::PyramidShardPlan plan(map, pyramid.options, pyramid.flakes, spec.count);
  bake::ndf::PyramidOptions opt = pyramid.options;
  opt.region_filter = plan.filter(spec.index);
  cli::ShardOutput out(t, output, spec, zstd_level);
  bake::ndf::ShardPyramidSink sink(out.partial());
  bake::ndf::PyramidReport report;
  cli::LevelProgress progress(t);
  const bake::BakeStatus built = bake::ndf::buildNdfPyramid(map, opt, sink, &report, progress.callback());
  progress.finish();
  cli::check(built);
  uint64_t flake_bytes = 0;
  if (pyramid.flakes) {
    if (plan.flakesOwner() == spec.index) {
      std::vector<uint8_t> section = cli::unwrap(
          bake::ndf::flakesSectionBytes(map, pyramid.options.rate, pyramid.options.splat.sigma_r, handover));
      flake_bytes = section.size();
      cli::check(out.partial().add(format::kSectionFlakes, 0, section.data(), section.size()));
    } else {
      format::FlakesRecord rec;
      rec.map_width = uint32_t(map.width);
      rec.map_height = uint32_t(map.height);
      flake_bytes = format::flakesSectionSize(rec);
      out.partial().skip();
    }
  }
  const uint64_t units = plan.unitsOf(spec.index);
  out.finish(assetMetadata(report, flake_bytes), format::AssetKind::kNdfPyramid, units, plan.units());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string which = std::to_string(spec.index) + "/" + std::to_string(spec.count);
  if (t.common().json) {
    Json doc;
    doc["tool"] = "ndfgen";
    doc["output"] = cli::baseName(output);
    doc["kind"] = "partial";
    doc["shard"] = {{"index", spec.index}, {"count", spec.count}};
    doc["units"] = units;
    doc["units_total"] = plan.units();
    double total = 0.0;
    for (int i = 0; i < spec.count; ++i) total += plan.costOf(i);
    doc["estimated_cost_share"] = total > 0.0 ? plan.costOf(spec.index) / total : 0.0;
    doc["sections_held"] = out.partial().held();
    doc["positions"] = out.partial().positions();
    doc["file_bytes"] = out.bytesWritten();
    doc["seconds"] = seconds;
    t.printJson(doc);
  } else {
    t.info("wrote " + output + ": shard " + which + " of an ndf-pyramid, " + std::to_string(units) + " of " +
           std::to_string(plan.units()) + " units, " + std::to_string(out.partial().held()) + " of " +
           std::to_string(out.partial().positions()) + " sections, " + std::to_string(out.bytesWritten()) +
           " bytes in " + std::to_string(seconds) + " s");
  }
  return cli::kExitOk;
}

}  // namespace

int glintbake::cli::ndfgenMain(int argc, char** argv) {
  cli::Tool tool("ndfgen", "Bakes the footprint pyramid of P-NDF images of a normal map (ndf-pyramid asset)");
  std::string input, output;
  bake::IngestOptions ingest;
  cli::PyramidCliOptions pyramid;
  const bake::ndf::PyramidOptions& opt = pyramid.options;
  int zstd_level = 3;
  tool.addExample("ndfgen brushed.png -o brushed.gbk", "Bake the footprint pyramid of a normal map.");
  tool.addExample("ndfgen brushed.png -o brushed.gbk --ndf-res 32 --depfile brushed.gbk.d -q",
                  "Smaller NDF images, a depfile for make or ninja, warnings only.");
  tool.addExample("ndfgen --procedural glitter -o glitter.gbk",
                  "The pyramid of a procedural glitter surface instead of a map.");
  CLI::App& app = tool.app();
  app.add_option("map", input, "Normal map (or height field with --height); none with --procedural");
  app.add_option("-o,--output", output, "Output ndf-pyramid container (.gbk)")->required();
  cli::addPyramidOptions(app, pyramid, "Footprint centres per side of a streamed chunk (1..256)");
  app.add_option("--zstd-level", zstd_level, "zstd compression level of the chunks (1..19)")->capture_default_str();
  cli::addIngestOptions(app, ingest);
  cli::GlitterCliOptions glitter;
  bool glitter_asset = false;
  cli::addGlitterOptions(app, glitter);
  app.add_flag("--glitter-asset", glitter_asset, "With --procedural glitter: write the surface as a glitter asset");
  cli::ShardCliOptions shard;
  cli::addShardOption(app, shard);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    const auto t0 = std::chrono::steady_clock::now();
    if (zstd_level < 1 || zstd_level > 19) throw Error(cli::kExitBadArguments, "--zstd-level must be in [1, 19]");
    cli::resolvePyramidOptions(pyramid);
    cli::resolveShardOption(shard);
    if (shard.active() && !glitter.procedural.empty())
      throw Error(cli::kExitUnsupported, "--shard bakes normal maps only (not --procedural)");
    if (!glitter.procedural.empty()) return bakeProcedural(t, glitter, glitter_asset, pyramid, output, zstd_level, t0);
    if (input.empty()) throw Error(cli::kExitBadArguments, "a normal map (or --procedural glitter) is required");
    if (glitter_asset) throw Error(cli::kExitBadArguments, "--glitter-asset needs --procedural glitter");

    bake::IngestReport ingest_report;
    const bake::NormalMap map = cli::loadNormalMapForTool(t, input, ingest, &ingest_report);
    cli::requireBakeableMap(map, input);
    cli::checkMemoryBudget(pyramid, map, t.threadCount(), /*tensor=*/false);

    const bake::ndf::FlakesHandover handover = cli::defaultFlakesHandover(pyramid, map);
    // The asset's metadata, the same whether one machine bakes it or a shard does.
    auto assetMetadata = [&](const bake::ndf::PyramidReport& report, uint64_t flake_bytes) {
      Json params = cli::pyramidOptionsJson(pyramid);
      params["zstd_level"] = zstd_level;
      params["ingest"] = cli::ingestOptionsJson(ingest);
      Json meta = t.makeMetadata(format::AssetKind::kNdfPyramid, params);
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
      return meta;
    };
    if (shard.active()) return bakeShard(t, map, pyramid, shard.spec, output, zstd_level, handover, assetMetadata, t0);

    cli::ContainerOutput out(t, output, format::AssetKind::kNdfPyramid, zstd_level);

    bake::ndf::PyramidReport report;
    cli::LevelProgress progress(t);
    const bake::BakeStatus built =
        bake::ndf::buildNdfPyramid(map, opt, out.writer(), &report, progress.callback(), cli::cancelFlag());
    progress.finish();
    cli::check(built);
    const uint64_t flake_bytes = cli::writeFlakes(out.writer(), map, pyramid, handover);
    const Json meta = assetMetadata(report, flake_bytes);
    const Json& params = meta["parameters"];
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
