// SPDX-License-Identifier: Apache-2.0
// tensorpack: compresses the footprint pyramid of NDF images of a normal map (built on the fly) or of
// an ndf-pyramid container into a tensor-ndf asset: per region and level, the non-blank B x B
// angular blocks as one rank-R CP model (libbake/tensor/tensor_pack.h; layout in formats/SPEC.md
// section 10.4).
#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/embed.h>
#include <glintbake/cli/glitter_options.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/cli/pyramid_options.h>
#include <glintbake/cli/stdin_input.h>
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

// Relative error above which tensorpack warns when no --error-target is given (README, "tensorpack
// defaults"). At rank 16 the real maps that CP compresses well land at 0.15-0.25
// (brushed_blender_1024 0.164, scratches_straight_cutlery_512 0.151), while a sharp-flake map lands
// at 0.93 (flakes_voronoi_sharp_snail_512; the example flakes asset 0.88): an asset that far off has
// lost most of its glints. 0.5 separates the two with room on both sides.
constexpr double kDefaultErrorBound = 0.5;
// Relative error (Frobenius, over a level's images) up to which a compressed level answers its
// footprints; below the first level from which every level meets it, the clustered lobes answer
// (README, "How an NDF asset answers a footprint").
constexpr double kFaithfulLevelError = 0.15;
// ... and at most this share of the level's variation (|D - mean image| / |D|): the footprints of
// a level differ from each other by about that much, which is what the smooth baseline misses, so
// an error near it keeps no more of the glints than one smooth image would. On the real maps of
// the fidelity table rank 16 stays near or above the variation at every level (README, "Figures").
constexpr double kFaithfulVariationShare = 0.25;

// How far a level is from faithful: at most 1 when it meets both bounds.
double unfaithfulness(const tensor::TensorPackLevelReport& l) {
  if (l.exact) return 0.0;
  const double by_norm = l.relative_error / kFaithfulLevelError;
  if (!(l.relative_error > 0.0)) return 0.0;
  if (!(l.variation > 0.0)) return std::numeric_limits<double>::infinity();
  return std::max(by_norm, l.relative_error / (kFaithfulVariationShare * l.variation));
}

std::string errorText(double e) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4f", e);
  return text;
}

// The error a gate compares: that of the compressed levels that answer footprints. Without lobes
// every level answers: the larger of the whole pyramid's relative error (dropped blocks included)
// and the largest group's (its kept blocks). With lobes, the levels the lobes stand in for never
// answer (compressedHandover): the largest relative error of the levels the pyramid blends in
// above lobes_up_to, or of the top level alone when the lobes answer every footprint their window
// allows (the top level answers beyond it).
struct GatedError {
  double error = 0.0;
  double from_sigma = 0.0;  // sigma of the first level gated
  bool whole = true;        // every level answers
};

GatedError gatedError(const tensor::TensorPackReport& r, const bake::ndf::FlakesHandover& h) {
  GatedError g;
  if (h.lobes_per_tile <= 0 || r.levels.empty()) {
    g.error = std::max(r.relative_error, r.max_group_error);
    return g;
  }
  g.whole = false;
  size_t first = r.levels.size() - 1;
  while (first > 0 && 2.0 * r.levels[first - 1].sigma > h.lobes_up_to) --first;
  g.from_sigma = r.levels[first].sigma;
  for (size_t l = first; l < r.levels.size(); ++l) g.error = std::max(g.error, r.levels[l].relative_error);
  return g;
}

std::string achievedText(const tensor::TensorPackReport& r, const GatedError& g) {
  if (g.whole)
    return "relative error " + errorText(r.relative_error) + " (largest group " + errorText(r.max_group_error) + ")";
  char sigma[32];
  std::snprintf(sigma, sizeof(sigma), "%g", g.from_sigma);
  return "relative error " + errorText(g.error) + " of the levels that answer footprints (sigma " + sigma +
         " and up; the clustered lobes answer below)";
}

// --max-error: fails (runtime failure, before anything is written) when the gated error exceeds E.
void checkMaxError(const tensor::TensorPackReport& r, const GatedError& g, double max_error, const std::string& input) {
  if (max_error < 0.0 || !(g.error > max_error)) return;
  throw Error(cli::kExitRuntime, input + ": " + achievedText(r, g) + " exceeds --max-error " + errorText(max_error) +
                                     "; no output written");
}

// One warning when the gated error misses --error-target (when given) or the default bound.
std::vector<std::string> qualityWarnings(const tensor::TensorPackReport& r, const GatedError& g, double error_target,
                                         int rank) {
  std::vector<std::string> warnings;
  if (error_target >= 0.0) {
    if (g.error > error_target) {
      warnings.push_back(achievedText(r, g) + " misses --error-target " + errorText(error_target) + " at --rank " +
                         std::to_string(rank));
    }
  } else if (g.error > kDefaultErrorBound) {
    warnings.push_back(achievedText(r, g) + " exceeds the default bound " + errorText(kDefaultErrorBound) +
                       " (raise --rank, or gate with --max-error)");
  }
  return warnings;
}

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
  j["exact"] = l.exact;
  return j;
}

Json rankHistogramJson(const tensor::TensorPackReport& r) {
  Json h = Json::object();
  for (const auto& [rank, groups] : r.rank_histogram) h[std::to_string(rank)] = groups;
  return h;
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
                 "(>= 0; unset: no gate). Without --error-target, errors above 0.5 warn");
  // Pyramid options: only for normal-map inputs (a container brings its own pyramid).
  cli::addPyramidOptions(app, o.pyramid, "Footprint centres per group side (1..256)");
  cli::addIngestOptions(app, o.ingest);
}

// Stage 1b: checks the parsed options and derives the library's (exit 1 on anything out of range).
void resolveOptions(const CLI::App& app, Options& o) {
  cli::resolveTensorPackOptions(app, o.tensor);
  if (app.count("--max-error") && !(o.max_error >= 0.0 && std::isfinite(o.max_error))) {
    throw Error(cli::kExitBadArguments, "--max-error must be a finite number >= 0");
  }
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
  // (side^2 R^2 4 bytes within the budget), so that the top level is not a lossy one.
  const double exact_side = std::sqrt(double(o.pack.exact_level_bytes) / (4.0 * double(ndf_res) * double(ndf_res)));
  o.pyramid.options.converge_from_grid = int(std::min(exact_side, 16.0));  // kMaxExactCentres = 16 x 16
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

// Stage 3: packs the input into the (temporary) output container; nothing is in place yet.
tensor::TensorPackReport packAsset(cli::Tool& t, const Options& o, Input& in, cli::ContainerOutput& out,
                                   bake::ndf::FlakesHandover& handover, uint64_t* flake_bytes) {
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
  // The flakes for exact small footprints (formats/SPEC.md 10.5), written from the map or carried
  // over from the source container, with the hand-over this compression calls for: the pyramid
  // answers only from the first level from which every level is faithful (unfaithfulness), the
  // clustered lobes below it.
  std::vector<double> sigmas, errors;
  std::unique_ptr<bool[]> exact(new bool[std::max<size_t>(report.levels.size(), 1)]);
  for (size_t l = 0; l < report.levels.size(); ++l) {
    sigmas.push_back(report.levels[l].sigma);
    errors.push_back(unfaithfulness(report.levels[l]));
    exact[l] = report.levels[l].exact;
  }
  const int lobes = in.from_container ? sourceLobesPerTile(in.reader, o.input) : o.pyramid.lobes;
  handover = bake::ndf::compressedHandover(sigmas.data(), errors.data(), int(sigmas.size()), 1.0, lobes, exact.get());
  if (in.source) {
    *flake_bytes = 0;  // a procedural surface has no map to carry
  } else if (!in.from_container) {
    *flake_bytes = cli::writeFlakes(out.writer(), in.map, o.pyramid, handover);
  } else if (const int idx = in.reader.find(format::kSectionFlakes, 0); idx >= 0) {
    std::vector<uint8_t> flakes;
    format::ContainerStatus st = in.reader.readSection(size_t(idx), &flakes);
    if (st == format::ContainerStatus::kOk) {
      format::FlakesRecord rec;
      if (flakes.size() < sizeof(rec))
        throw Error(cli::kExitInvalidInput, o.input + ": the flakes section is truncated");
      std::memcpy(&rec, flakes.data(), sizeof(rec));
      rec.version = format::FlakesRecord().version;
      rec.flakes_up_to = handover.flakes_up_to;
      rec.lobes_per_tile = uint32_t(handover.lobes_per_tile);
      rec.lobes_up_to = handover.lobes_per_tile > 0 ? handover.lobes_up_to : 0.0;
      rec.pyramid_from = handover.pyramid_from;
      if (const char* why = format::checkFlakesRecord(rec, flakes.size()))
        throw Error(cli::kExitInvalidInput, o.input + ": " + why);
      std::memcpy(flakes.data(), &rec, sizeof(rec));
      st = out.writer().addSection(format::kSectionFlakes, 0, flakes.data(), flakes.size());
      *flake_bytes = flakes.size();
    }
    if (st != format::ContainerStatus::kOk)
      throw Error(cli::kExitIo, o.input + ": cannot carry over the flakes section: " + format::statusString(st));
  }
  return report;
}

// Stage 4: the asset's metadata; adds it and renames the container into place.
void writeAsset(cli::Tool& t, const Options& o, const Input& in, const Json& params,
                const tensor::TensorPackReport& report, const Json& flakes, cli::ContainerOutput& out) {
  Json asset;
  asset["ndf_res"] = report.ndf_res;
  asset["block"] = o.pack.block;
  asset["blocks_per_side"] = report.blocks_per_side;
  asset["levels"] = Json::array();
  for (const auto& l : report.levels) {
    asset["levels"].push_back({{"level", l.level}, {"grid", {l.grid_width, l.grid_height}}, {"groups", l.groups}});
  }
  asset["groups"] = report.groups;
  asset["max_rank"] = report.max_rank;
  asset["rank_histogram"] = rankHistogramJson(report);
  asset["precision"] = o.tensor.precision_text;
  asset["nonneg"] = o.pack.cp.nonneg;
  asset["blank_threshold"] = o.pack.blank_threshold;
  if (!flakes.is_null()) asset["flakes"] = flakes;
  asset["relative_error"] = report.relative_error;
  if (!in.map_json.is_null()) asset["map"] = in.map_json;
  if (in.source_asset.is_object()) {
    for (const char* key : {"map_size", "wrap", "sigma_r", "rate"}) {
      if (in.source_asset.contains(key)) asset[key] = in.source_asset[key];
    }
  }
  Json meta = t.makeMetadata("tensor-ndf", params);
  meta["asset"] = asset;
  out.finish(meta);
}

// Stage 5: the warnings, then the --json summary or the one-line summary.
void printReport(cli::Tool& t, const Options& o, const Input& in, const Json& params,
                 const tensor::TensorPackReport& report, const GatedError& gated,
                 const std::vector<std::string>& warnings, uint64_t file_bytes, double seconds) {
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
  doc["rank_histogram"] = rankHistogramJson(report);
  doc["max_rank"] = report.max_rank;
  doc["gated_error"] = {{"error", gated.error}, {"from_sigma", gated.whole ? Json(nullptr) : Json(gated.from_sigma)}};
  doc["raw_bytes"] = report.raw_bytes;
  doc["stored_bytes"] = report.stored_bytes;
  doc["file_bytes"] = file_bytes;
  doc["ratio"] = ratio;
  doc["relative_error"] = report.relative_error;
  doc["max_group_error"] = report.max_group_error;
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
  addOptions(tool.app(), o);
  return tool.run(argc, argv, [&](cli::Tool& t) {
    const auto t0 = std::chrono::steady_clock::now();
    resolveOptions(t.app(), o);
    Json params = parametersJson(o);
    Input in;
    readInput(t, o, in, params);
    cli::ContainerOutput out(t, o.output, format::AssetKind::kTensorNdf, o.tensor.zstd_level);
    bake::ndf::FlakesHandover handover;
    uint64_t flake_bytes = 0;
    const tensor::TensorPackReport report = packAsset(t, o, in, out, handover, &flake_bytes);
    // The gate runs before anything is in place: a failure leaves no output.
    const GatedError gated = gatedError(report, handover);
    checkMaxError(report, gated, o.max_error, o.input);
    const std::vector<std::string> warnings = qualityWarnings(report, gated, o.tensor.error_target, o.pack.cp.rank);
    const Json flakes = flake_bytes > 0 ? cli::flakesJson(handover, flake_bytes) : Json(nullptr);
    writeAsset(t, o, in, params, report, flakes, out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    printReport(t, o, in, params, report, gated, warnings, out.bytesWritten(), seconds);
    return cli::kExitOk;
  });
}
