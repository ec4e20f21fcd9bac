// SPDX-License-Identifier: Apache-2.0
// tensorpack: compresses the footprint pyramid of NDF images of a normal map (built on the fly) or of
// an ndf-pyramid container into a tensor-ndf asset: per region and level, the non-blank B x B
// angular blocks as one rank-R CP model (libbake/tensor/tensor_pack.h; layout in formats/SPEC.md
// section 10.4).
#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/bake/tensor/tensor_shard.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/embed.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/glitter_options.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/cli/pyramid_options.h>
#include <glintbake/cli/shard_output.h>
#include <glintbake/cli/stdin_input.h>
#include <glintbake/cli/tensor_asset.h>
#include <glintbake/cli/tensor_options.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>
#include <glintbake/format/json_depth.h>
#include <glintbake/format/kinds/flakes.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace {

using glintbake::cli::Error;
using glintbake::cli::GatedError;
using glintbake::cli::Json;
namespace bake = glintbake::bake;
namespace cli = glintbake::cli;
namespace format = glintbake::format;
namespace tensor = glintbake::bake::tensor;

// True when the file starts with the container magic. Throws the I/O error for unreadable files.
bool isContainer(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error(cli::kExitIo, path + ": cannot open (missing or unreadable)");
  unsigned char head[8] = {};
  f.read(reinterpret_cast<char*>(head), sizeof(head));
  return format::hasContainerMagic(head, size_t(f.gcount()));
}

// Default output: beside the input, its extension replaced by .gbk (a container input keeps its
// name and gets .tensor.gbk, so it is never overwritten).
std::string defaultOutput(const std::string& input, bool container) {
  const size_t slash = input.find_last_of("/\\");
  const size_t dot = input.find_last_of('.');
  const std::string stem =
      (dot != std::string::npos && (slash == std::string::npos || dot > slash)) ? input.substr(0, dot) : input;
  return stem + (container ? ".tensor.gbk" : ".gbk");
}

int exitCodeOf(const bake::Error& e) { return int(e.code); }

Json levelJson(const tensor::TensorPackLevelReport& l) {
  Json j;
  j["level"] = l.level;
  j["sigma"] = l.sigma;
  j["grid"] = {l.grid_width, l.grid_height};
  j["groups"] = l.groups;
  j["blocks_kept"] = l.blocks_kept;
  j["blocks_dropped"] = l.blocks_dropped;
  j["raw_bytes"] = l.raw_bytes;
  j["stored_bytes"] = l.stored_bytes;
  j["relative_error"] = l.relative_error;
  j["variation"] = l.variation;
  j["l1_error"] = l.l1_error;
  j["exact"] = l.exact;
  return j;
}

// Everything the command line sets; filled by CLI11 (addOptions) and checked by resolveOptions.
struct Options {
  std::string input, output;
  bake::IngestOptions ingest;
  cli::PyramidCliOptions pyramid;
  cli::GlitterCliOptions glitter;
  cli::TensorCliOptions tensor;
  tensor::TensorPackOptions& pack = tensor.pack;
  double max_error = -1.0;
  cli::ShardCliOptions shard;
};

// Stage 1a: registers the options.
void addOptions(CLI::App& app, Options& o) {
  app.add_option("input", o.input,
                 "Normal map (or height field with --height), or an ndf-pyramid container (.gbk); none with "
                 "--procedural");
  cli::addGlitterOptions(app, o.glitter);
  app.add_option("-o,--output", o.output, "Output tensor-ndf container (default: the input's name with .gbk)");
  cli::addTensorPackOptions(app, o.tensor);
  app.add_option("--max-error", o.max_error,
                 "Fail (exit 4, no output) when the relative error of the pyramid or of any group exceeds this "
                 "(>= 0; unset: no gate; with --shard, glintinfo merge applies it). Without --error-target, errors "
                 "above 0.5 warn");
  // Pyramid options: only for normal-map inputs (a container brings its own pyramid).
  cli::addPyramidOptions(app, o.pyramid, "Footprint centres per group side (1..256)");
  cli::addIngestOptions(app, o.ingest);
  cli::addShardOption(app, o.shard);
}

// Stage 1b: checks the parsed options and derives the library's (exit 1 on anything out of range).
void resolveOptions(const CLI::App& app, Options& o) {
  cli::resolveTensorPackOptions(app, o.tensor);
  if (app.count("--max-error") && !(o.max_error >= 0.0 && std::isfinite(o.max_error))) {
    throw Error(cli::kExitBadArguments, "--max-error must be a finite number >= 0");
  }
  cli::resolveShardOption(o.shard);
}

// Canonical parameters (container metadata and --json), in their recorded order; readInput adds
// "pyramid" and "source".
Json parametersJson(const Options& o) { return cli::tensorPackOptionsJson(o.tensor); }

// The input: an ndf-pyramid container (open reader) or a loaded normal map.
struct Input {
  bool from_container = false;
  std::unique_ptr<bake::glitter::GlitterModel> glitter;  // --procedural glitter
  std::unique_ptr<bake::glitter::GlitterImageSource> source;
  format::Reader reader;
  bake::NormalMap map;
  Json map_json = nullptr, source_asset = nullptr;
};

// Stage 2: opens the container, or loads the normal map, and completes the parameters.
void readInput(cli::Tool& t, Options& o, Input& in, Json& params) {
  if (!o.glitter.procedural.empty()) {
    if (!o.input.empty()) throw Error(cli::kExitBadArguments, "--procedural takes no input file");
    if (o.output.empty()) throw Error(cli::kExitBadArguments, "--procedural needs -o/--output");
    cli::resolvePyramidOptions(o.pyramid);
    const int res = o.pyramid.options.splat.ndf_res;
    if (res % o.pack.block != 0) {
      throw Error(cli::kExitBadArguments,
                  "--block " + std::to_string(o.pack.block) + " must divide --ndf-res " + std::to_string(res));
    }
    const bake::glitter::GlitterParams gp = cli::resolveGlitterOptions(o.glitter, res);
    in.glitter = std::make_unique<bake::glitter::GlitterModel>(gp);
    in.source = std::make_unique<bake::glitter::GlitterImageSource>(*in.glitter, res, o.pyramid.options.sigma0);
    in.map_json = {{"width", gp.map_width}, {"height", gp.map_height}, {"wrap", "repeat"}};
    params["pyramid"] = cli::pyramidOptionsJson(o.pyramid);
    params["glitter"] = cli::glitterParamsJson(gp);
    params["source"] = "glitter";
    return;
  }
  if (o.input.empty()) throw Error(cli::kExitBadArguments, "an input (or --procedural glitter) is required");
  if (o.input == "-" && o.output.empty())
    throw Error(cli::kExitBadArguments, "-o is required when the input is standard input ('-')");
  o.input = cli::resolveInput(o.input);
  in.from_container = isContainer(o.input);
  if (o.output.empty()) o.output = defaultOutput(o.input, in.from_container);
  if (in.from_container) {
    for (CLI::Option* flag : o.pyramid.flags) {
      if (flag->count() > 0)
        throw Error(cli::kExitBadArguments, flag->get_name() + " applies to normal-map inputs only");
    }
    t.addInput(o.input);
    if (format::ContainerStatus st = in.reader.open(o.input); st != format::ContainerStatus::kOk) {
      const int code = st == format::ContainerStatus::kIoError              ? cli::kExitIo
                       : st == format::ContainerStatus::kUnsupportedVersion ? cli::kExitUnsupported
                                                                            : cli::kExitInvalidInput;
      throw Error(code, o.input + ": " + format::statusString(st));
    }
    if (in.reader.kind() != format::AssetKind::kNdfPyramid) {
      throw Error(cli::kExitInvalidInput, o.input + ": not an ndf-pyramid container (asset kind " +
                                              format::assetKindString(in.reader.kind()) + ")");
    }
    std::string meta_text;
    if (in.reader.readMetadata(&meta_text) == format::ContainerStatus::kOk &&
        format::jsonNestingDepth(meta_text) <= size_t(format::kMaxJsonDepth)) {
      const Json source = Json::parse(meta_text, nullptr, false);
      if (source.is_object() && source.contains("parameters")) params["pyramid"] = source["parameters"];
      if (source.is_object() && source.contains("asset")) in.source_asset = source["asset"];
    }
    params["source"] = "ndf-pyramid";
    return;
  }
  cli::resolvePyramidOptions(o.pyramid);
  const int ndf_res = o.pyramid.options.splat.ndf_res;
  // The automatic level count may stop only once the pyramid has reached the levels stored exactly
  // (side^2 R^2 4 bytes within the budget), so that the top level is not a lossy one, and never
  // before its top grid fits the runtime's whole-grid blend (the builder's default).
  const double exact_side = std::sqrt(double(o.pack.exact_level_bytes) / (4.0 * double(ndf_res) * double(ndf_res)));
  const int exact_grid = int(std::min(exact_side, 16.0));  // kMaxExactCentres = 16 x 16
  if (exact_grid >= 1)
    o.pyramid.options.converge_from_grid = std::min(exact_grid, o.pyramid.options.converge_from_grid);
  o.pyramid.options.converge_from_level = o.pack.exact_level_bytes > 0 ? 1 : 0;
  if (ndf_res % o.pack.block != 0) {
    throw Error(cli::kExitBadArguments,
                "--block " + std::to_string(o.pack.block) + " must divide --ndf-res " + std::to_string(ndf_res));
  }
  bake::IngestReport ingest_report;
  in.map = cli::loadNormalMapForTool(t, o.input, o.ingest, &ingest_report);
  cli::requireBakeableMap(in.map, o.input);
  cli::checkMemoryBudget(o.pyramid, in.map, t.threadCount(), /*tensor=*/true);
  in.map_json = {{"width", in.map.width}, {"height", in.map.height}, {"wrap", bake::wrapString(in.map.wrap)}};
  Json p = cli::pyramidOptionsJson(o.pyramid);
  p["ingest"] = cli::ingestOptionsJson(o.ingest);
  params["pyramid"] = p;
  params["source"] = "normal-map";
}

// The lobes per tile the source container's flakes record asks for (what its ndfgen --lobes was);
// 0 without a flakes section.
int sourceLobesPerTile(const format::Reader& reader, const std::string& input) {
  const int idx = reader.find(format::kSectionFlakes, 0);
  if (idx < 0) return 0;
  std::vector<uint8_t> flakes;
  if (reader.readSection(size_t(idx), &flakes) != format::ContainerStatus::kOk ||
      flakes.size() < sizeof(format::FlakesRecord))
    throw Error(cli::kExitInvalidInput, input + ": the flakes section is unreadable or truncated");
  format::FlakesRecord rec;
  std::memcpy(&rec, flakes.data(), sizeof(rec));
  return rec.version >= 2 ? int(rec.lobes_per_tile) : 0;
}

// The raw flakes section of a map (unless --no-flakes), with the default hand-over in its record
// until finishTensorAsset sets the one the compression calls for.
std::vector<uint8_t> mapFlakes(const Options& o, const bake::NormalMap& map) {
  if (!o.pyramid.flakes) return {};
  bake::ndf::FlakesHandover provisional = cli::defaultFlakesHandover(o.pyramid, map);
  provisional.tile_ratio_milli = format::kDefaultFlakesTileRatioMilli;  // (chosen with the final hand-over)
  return cli::unwrap(
      bake::ndf::flakesSectionBytes(map, o.pyramid.options.rate, o.pyramid.options.splat.sigma_r, provisional));
}

// What the end of the bake needs besides the report (the same on one machine and in the merge).
cli::TensorAssetEnd assetEnd(const Options& o, const Input& in) {
  cli::TensorAssetEnd end;
  end.lobes_per_tile = in.from_container ? sourceLobesPerTile(in.reader, o.input) : o.pyramid.lobes;
  end.max_error = o.max_error;
  end.error_target = o.tensor.error_target;
  end.rank = o.pack.cp.rank;
  end.label = o.input;
  return end;
}

// The asset's metadata without what the compression decides (finishTensorAsset adds it).
Json metadataTemplate(cli::Tool& t, const Options& o, const Input& in, const Json& params) {
  Json asset;
  asset["block"] = o.pack.block;
  asset["precision"] = o.tensor.precision_text;
  asset["nonneg"] = o.pack.cp.nonneg;
  asset["blank_threshold"] = o.pack.blank_threshold;
  if (!in.map_json.is_null()) asset["map"] = in.map_json;
  if (in.source_asset.is_object()) {
    for (const char* key : {"map_size", "wrap", "sigma_r", "rate"}) {
      if (in.source_asset.contains(key)) asset[key] = in.source_asset[key];
    }
  }
  Json meta = t.makeMetadata("tensor-ndf", params);
  meta["asset"] = asset;
  return meta;
}

// Stage 3: packs the input into the (temporary) output container; nothing is in place yet. The
// flakes section's raw bytes (from the map, or carried over from the source container) go to
// *flakes, for finishTensorAsset to complete with the hand-over.
tensor::TensorPackReport packAsset(cli::Tool& t, const Options& o, Input& in, cli::ContainerOutput& out,
                                   std::vector<uint8_t>* flakes) {
  tensor::TensorPackReport report;
  bake::BakeStatus s = bake::okStatus();
  if (in.source) {
    cli::LevelProgress progress(t);
    s = tensor::packTensorNdfFromSource(*in.source, o.pyramid.options, o.pack, out.writer(), &report,
                                        progress.callback(), cli::cancelFlag());
    progress.finish();
  } else if (in.from_container) {
    s = tensor::packTensorNdfFromPyramid(in.reader, o.pack, out.writer(), &report, cli::cancelFlag());
  } else {
    cli::LevelProgress progress(t);
    s = tensor::packTensorNdfFromMap(in.map, o.pyramid.options, o.pack, out.writer(), &report, progress.callback(),
                                     cli::cancelFlag());
    progress.finish();
  }
  if (!s) throw Error(exitCodeOf(s.error()), o.input + ": " + s.error().message);
  if (in.source) return report;  // a procedural surface has no map to carry
  if (!in.from_container) {
    *flakes = mapFlakes(o, in.map);
  } else if (const int idx = in.reader.find(format::kSectionFlakes, 0); idx >= 0) {
    if (format::ContainerStatus st = in.reader.readSection(size_t(idx), flakes); st != format::ContainerStatus::kOk)
      throw Error(cli::kExitIo, o.input + ": cannot carry over the flakes section: " + format::statusString(st));
  }
  return report;
}

// Stage 4: completes the asset (hand-over, gate, flakes, metadata), adds the metadata and renames
// the container into place.
cli::TensorAssetResult writeAsset(const Options& o, const Input& in, const tensor::TensorPackReport& report,
                                  std::vector<uint8_t>& flakes, const Json& metadata, cli::ContainerOutput& out) {
  cli::TensorAssetResult done = cli::finishTensorAsset(out.writer(), report, &flakes, metadata, assetEnd(o, in));
  out.finish(done.metadata);
  return done;
}

// tensorpack --shard I/N: the regions (and maybe the flakes) the plan gives this shard, their
// results recorded for the merge to replay (bake/tensor/tensor_shard.h).
cli::ExitCode bakeShard(cli::Tool& t, const Options& o, Input& in, const Json& metadata,
                        std::chrono::steady_clock::time_point t0) {
  const cli::ShardCliOptions& shard = o.shard;
  const cli::PyramidShardPlan plan(in.map, o.pyramid.options, o.pyramid.flakes, shard.spec.count);
  bake::ndf::PyramidOptions opt = o.pyramid.options;
  opt.region_filter = plan.filter(shard.spec.index);
  cli::ShardOutput out(t, o.output, shard.spec, o.tensor.zstd_level);
  tensor::TensorShardRecorder recorder(out.writer(), o.tensor.zstd_level, o.pack.block,
                                       [&plan](int level, int region) { return plan.unit(level, region); });
  tensor::TensorPackReport report;
  cli::LevelProgress progress(t);
  const bake::BakeStatus s =
      tensor::packTensorNdfFromMap(in.map, opt, o.pack, recorder, &report, progress.callback(), cli::cancelFlag());
  progress.finish();
  if (!s) throw Error(exitCodeOf(s.error()), o.input + ": " + s.error().message);
  cli::check(recorder.finish());
  // Units the plan gives this shard (as ndfgen counts them: those of levels the bake stopped
  // before included); sections_held counts the units recorded.
  const uint64_t units = plan.unitsOf(shard.spec.index);
  uint64_t held = recorder.regionsHeld();
  if (o.pyramid.flakes && plan.flakesOwner() == shard.spec.index) {
    const std::vector<uint8_t> flakes = mapFlakes(o, in.map);
    out.addUnit(uint64_t(plan.flakesUnit()), flakes.data(), flakes.size());
    ++held;
  }
  const cli::TensorAssetEnd end = assetEnd(o, in);
  Json assembly = cli::tensorShardAssembly(o.pack, end, o.pyramid.flakes);
  out.finish(metadata, format::AssetKind::kTensorNdf, units, plan.units(), assembly);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (t.common().json) {
    Json doc;
    doc["tool"] = "tensorpack";
    doc["output"] = cli::baseName(o.output);
    doc["kind"] = "partial";
    doc["shard"] = {{"index", shard.spec.index}, {"count", shard.spec.count}};
    doc["units"] = units;
    doc["units_total"] = plan.units();
    double total = 0.0;
    for (int i = 0; i < shard.spec.count; ++i) total += plan.costOf(i);
    doc["estimated_cost_share"] = total > 0.0 ? plan.costOf(shard.spec.index) / total : 0.0;
    doc["sections_held"] = held;
    doc["positions"] = 0;
    doc["file_bytes"] = out.bytesWritten();
    doc["seconds"] = seconds;
    t.printJson(doc);
  } else {
    t.info("wrote " + o.output + ": shard " + std::to_string(shard.spec.index) + "/" +
           std::to_string(shard.spec.count) + " of a tensor-ndf, " + std::to_string(units) + " of " +
           std::to_string(plan.units()) + " units, " + std::to_string(out.bytesWritten()) + " bytes in " +
           std::to_string(seconds) + " s");
  }
  return cli::kExitOk;
}

// Stage 5: the warnings, then the --json summary or the one-line summary.
void printReport(cli::Tool& t, const Options& o, const Input& in, const Json& params,
                 const tensor::TensorPackReport& report, const cli::TensorAssetResult& done, uint64_t file_bytes,
                 double seconds) {
  const GatedError& gated = done.gated;
  const std::vector<std::string>& warnings = done.warnings;
  for (const std::string& w : warnings) t.warning(o.input + ": " + w);
  const double ratio = report.raw_bytes > 0 ? double(file_bytes) / double(report.raw_bytes) : 0.0;
  if (!t.common().json) {
    char summary[256];
    std::snprintf(summary, sizeof(summary),
                  ": %zu levels, %llu groups (rank <= %d), %llu bytes = %.2f%% of the raw float32 NDF images, "
                  "relative error %.4f, %.1f s",
                  report.levels.size(), static_cast<unsigned long long>(report.groups), report.max_rank,
                  static_cast<unsigned long long>(file_bytes), 100.0 * ratio, report.relative_error, seconds);
    t.info("wrote " + o.output + summary);
    return;
  }
  Json doc;
  doc["tool"] = "tensorpack";
  doc["input"] = in.source ? std::string("glitter") : cli::baseName(o.input);
  doc["output"] = cli::baseName(o.output);
  doc["source"] = in.source ? "glitter" : in.from_container ? "ndf-pyramid" : "normal-map";
  doc["map"] = in.map_json;
  doc["parameters"] = params;
  doc["ndf_res"] = report.ndf_res;
  Json levels = Json::array();
  for (const auto& l : report.levels) levels.push_back(levelJson(l));
  doc["levels"] = levels;
  doc["groups"] = report.groups;
  doc["blocks_kept"] = report.blocks_kept;
  doc["blocks_dropped"] = report.blocks_dropped;
  doc["rank_histogram"] = cli::rankHistogramJson(report);
  doc["max_rank"] = report.max_rank;
  doc["gated_error"] = {{"error", gated.error}, {"from_sigma", gated.whole ? Json(nullptr) : Json(gated.from_sigma)}};
  doc["raw_bytes"] = report.raw_bytes;
  doc["stored_bytes"] = report.stored_bytes;
  doc["file_bytes"] = file_bytes;
  doc["ratio"] = ratio;
  doc["relative_error"] = report.relative_error;
  doc["max_group_error"] = report.max_group_error;
  Json probes = Json::array();
  for (const bake::ndf::HandoverProbe& p : done.probes) {
    if (!p.ran) continue;
    probes.push_back({{"sigma", p.sigma},
                      {"blend_error", p.blend_error},
                      {"lobes_error", p.lobes_error},
                      {"baseline", p.baseline},
                      {"answers", p.lobesAnswer() ? "lobes" : "pyramid"}});
  }
  doc["handover_probes"] = probes;
  doc["negative_mass_fraction"] = report.negative_mass_fraction;
  doc["warnings"] = warnings;
  doc["seconds"] = {{"ndf", report.ndf_seconds},   {"cp", report.cp_seconds},      {"write", report.write_seconds},
                    {"wait", report.wait_seconds}, {"pack", report.total_seconds}, {"total", seconds}};
  t.printJson(doc);
}

}  // namespace

int glintbake::cli::tensorpackMain(int argc, char** argv) {
  cli::Tool tool(
      "tensorpack",
      "Compresses the NDF footprint pyramid of a normal map or ndf-pyramid container into a tensor-ndf asset");
  Options o;
  tool.addExample("tensorpack brushed.png -o brushed-t.gbk",
                  "Bake and compress a normal map into a tensor-ndf asset in one step.");
  tool.addExample("tensorpack brushed.gbk --rank 16 --strict",
                  "Compress an ndf-pyramid asset; fail if the fit misses its error bound.");
  tool.addExample("tensorpack hero.png -o hero.2.part.gbk --shard 2/8",
                  "Bake shard 2 of 8 of a map; glintinfo merge joins the 8 parts into hero.gbk.");
  addOptions(tool.app(), o);
  return tool.run(argc, argv, [&](cli::Tool& t) {
    const auto t0 = std::chrono::steady_clock::now();
    resolveOptions(t.app(), o);
    Json params = parametersJson(o);
    Input in;
    readInput(t, o, in, params);
    if (o.shard.active() && (in.source || in.from_container))
      throw Error(cli::kExitUnsupported, "--shard bakes normal maps only (not --procedural or a container)");
    const Json metadata = metadataTemplate(t, o, in, params);
    if (o.shard.active()) return bakeShard(t, o, in, metadata, t0);
    cli::ContainerOutput out(t, o.output, format::AssetKind::kTensorNdf, o.tensor.zstd_level);
    std::vector<uint8_t> flakes;
    const tensor::TensorPackReport report = packAsset(t, o, in, out, &flakes);
    const cli::TensorAssetResult done = writeAsset(o, in, report, flakes, metadata, out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    printReport(t, o, in, params, report, done, out.bytesWritten(), seconds);
    return cli::kExitOk;
  });
}
