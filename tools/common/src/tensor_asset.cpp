// SPDX-License-Identifier: Apache-2.0
// The end of a tensor-ndf bake (cli/tensor_asset.h): hand-over, gate, flakes and metadata.
#include <glintbake/cli/tensor_asset.h>

#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/pyramid_options.h>
#include <glintbake/format/kinds/flakes.h>
#include <glintbake/format/kinds/tensor_ndf.h>
#include <glintbake/runtime/texel_source.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>

namespace glintbake::cli {
namespace {

namespace tensor = bake::tensor;

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

// ... and a mean relative L1 error of its images of at most this. The fidelity targets are on the
// L1 error of a footprint's image (median 0.12); a level's images enter a footprint's blend with
// their compression error nearly whole, and the blend between centres adds its own. The Frobenius
// bounds alone are blind to what CP does on maps of one dominant peak: on the curved-scratches map
// of the demo data rank 16 keeps levels 0 and 1 at Frobenius 0.052 and 0.035 (a tenth of their
// variation) while their images are 0.40 and 0.30 off in L1, and footprints of 16-40 texels were
// answered from them at 0.20-0.32.
constexpr double kFaithfulL1Error = 0.06;

// How far a level is from faithful: at most 1 when it meets every bound.
double unfaithfulness(const tensor::TensorPackLevelReport& l) {
  if (l.exact) return 0.0;
  if (!(l.relative_error > 0.0) && !(l.l1_error > 0.0)) return 0.0;
  if (!(l.variation > 0.0)) return std::numeric_limits<double>::infinity();
  return std::max({l.relative_error / kFaithfulLevelError, l.relative_error / (kFaithfulVariationShare * l.variation),
                   l.l1_error / kFaithfulL1Error});
}

std::string errorText(double e) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4f", e);
  return text;
}

}  // namespace

// The error a gate compares: that of the compressed levels that answer footprints. Without lobes
// every level answers: the larger of the whole pyramid's relative error (dropped blocks included)
// and the largest group's (its kept blocks). With lobes, the levels the lobes stand in for never
// answer (compressedHandover): the largest relative error of the levels the pyramid blends in
// above lobes_up_to, or of the top level alone when the lobes answer every footprint their window
// allows (the top level answers beyond it).
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

namespace {

// --max-error: fails (runtime failure, before anything is written) when the gated error exceeds E.
void checkMaxError(const tensor::TensorPackReport& r, const GatedError& g, double max_error, const std::string& input) {
  if (max_error < 0.0 || !(g.error > max_error)) return;
  throw Error(kExitRuntime, input + ": " + achievedText(r, g) + " exceeds --max-error " + errorText(max_error) +
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

}  // namespace

Json rankHistogramJson(const tensor::TensorPackReport& r) {
  Json h = Json::object();
  for (const auto& [rank, groups] : r.rank_histogram) h[std::to_string(rank)] = groups;
  return h;
}

bake::ndf::FlakesHandover tensorHandover(const tensor::TensorPackReport& report, int lobes_per_tile,
                                         const runtime::TexelSource* texels, int rate, double sigma_r,
                                         std::vector<bake::ndf::HandoverProbe>* probes) {
  std::vector<double> sigmas, errors;
  std::unique_ptr<bool[]> exact(new bool[std::max<size_t>(report.levels.size(), 1)]);
  for (size_t l = 0; l < report.levels.size(); ++l) {
    sigmas.push_back(report.levels[l].sigma);
    errors.push_back(unfaithfulness(report.levels[l]));
    // A level 0 stored exactly (a map of a few dozen texels) is faithful, but the lobes answer its
    // footprints from single flakes, closer than the blend of its few centres (on a 37 x 23 map
    // 0.11 relative L1 at 12 texels where the lobes give 0.03): it never moves the lobes' bound
    // below the default.
    exact[l] = report.levels[l].exact && l > 0;
  }
  // Above the first faithful level, when it is exact (and above the next while the lobes win):
  // whether the lobes or the pyramid's blend should answer, measured on the map.
  // The pyramid answers from the first exact level whichever level is probed (the runtime's blend
  // takes the finest level whose spread allows it, which above twice a level is often that one).
  int from = -1;
  auto blend_loses = [&](int level) {
    if (!texels) return false;
    if (from < 0) from = level;
    std::vector<bake::ndf::PyramidLevelShape> shapes;
    for (size_t l = size_t(from); l < report.levels.size(); ++l)
      shapes.push_back({report.levels[l].sigma, report.levels[l].grid_width, report.levels[l].grid_height});
    const bake::ndf::HandoverProbe p =
        bake::ndf::probeExactLevelHandover(*texels, rate, sigma_r, lobes_per_tile, shapes.data(), int(shapes.size()),
                                           std::sqrt(2.0) * report.levels[size_t(level)].sigma);
    if (probes) probes->push_back(p);
    return p.lobesAnswer();
  };
  return bake::ndf::compressedHandover(sigmas.data(), errors.data(), int(sigmas.size()), 1.0, lobes_per_tile,
                                       exact.get(), blend_loses);
}

TensorAssetResult finishTensorAsset(format::Writer& writer, const tensor::TensorPackReport& report,
                                    std::vector<uint8_t>* flakes, const Json& metadata, const TensorAssetEnd& end) {
  TensorAssetResult out;
  // The hand-over this compression calls for: the pyramid answers only from the first level from
  // which every level is faithful (unfaithfulness), the clustered lobes below it.
  if (flakes && flakes->size() >= sizeof(format::FlakesRecord)) {
    format::FlakesRecord rec;
    std::memcpy(&rec, flakes->data(), sizeof(rec));
    const uint64_t normals = uint64_t(rec.map_width) * uint64_t(rec.map_height) * 2 * sizeof(float);
    if (flakes->size() - sizeof(rec) >= normals) {
      const runtime::InterleavedTexels texels(int(rec.map_width), int(rec.map_height), rec.wrap == 0,
                                              reinterpret_cast<const float*>(flakes->data() + sizeof(rec)), 2);
      out.handover = tensorHandover(report, end.lobes_per_tile, &texels, int(rec.rate), rec.sigma_r, &out.probes);
    } else {
      out.handover = tensorHandover(report, end.lobes_per_tile);
    }
    out.handover = bake::ndf::fitHandoverToMap(out.handover, int(rec.map_width), int(rec.map_height), rec.wrap == 0,
                                               int(rec.rate));
  } else {
    out.handover = tensorHandover(report, end.lobes_per_tile);
  }
  // The gate runs before anything more is written: a failure leaves no output.
  out.gated = gatedError(report, out.handover);
  checkMaxError(report, out.gated, end.max_error, end.label);
  out.warnings = qualityWarnings(report, out.gated, end.error_target, end.rank);
  if (flakes && !flakes->empty()) {
    if (bake::BakeStatus s = bake::ndf::setFlakesHandover(*flakes, out.handover); !s)
      throw Error(kExitInvalidInput, end.label + ": " + s.error().message);
    if (format::ContainerStatus st = writer.addSection(format::kSectionFlakes, 0, flakes->data(), flakes->size());
        st != format::ContainerStatus::kOk)
      throw Error(kExitIo, end.label + ": cannot write the flakes section: " + writer.errorString(st));
    out.flake_bytes = flakes->size();
  }

  // The results, merged into the template's `asset` in the order the fields have always had (the
  // metadata is an ordered object: its text, and so the file, depends on the order).
  Json results = Json::object();
  results["ndf_res"] = report.ndf_res;
  results["blocks_per_side"] = report.blocks_per_side;
  results["levels"] = Json::array();
  for (const auto& l : report.levels) {
    results["levels"].push_back({{"level", l.level}, {"grid", {l.grid_width, l.grid_height}}, {"groups", l.groups}});
  }
  results["groups"] = report.groups;
  results["max_rank"] = report.max_rank;
  results["rank_histogram"] = rankHistogramJson(report);
  if (out.flake_bytes > 0) results["flakes"] = flakesJson(out.handover, out.flake_bytes);
  results["relative_error"] = report.relative_error;
  static const char* const kOrder[] = {"ndf_res", "block",           "blocks_per_side", "levels",
                                       "groups",  "max_rank",        "rank_histogram",  "precision",
                                       "nonneg",  "blank_threshold", "flakes",          "relative_error"};
  const Json& given = metadata.contains("asset") ? metadata["asset"] : Json::object();
  Json asset = Json::object();
  for (const char* key : kOrder) {
    if (results.contains(key)) {
      asset[key] = results[key];
    } else if (given.contains(key)) {
      asset[key] = given[key];
    }
  }
  for (auto it = given.begin(); it != given.end(); ++it) {
    if (!asset.contains(it.key())) asset[it.key()] = it.value();
  }
  out.metadata = metadata;
  out.metadata["asset"] = asset;
  return out;
}

Json tensorShardAssembly(const tensor::TensorPackOptions& pack, const TensorAssetEnd& end, bool flakes) {
  Json a;
  a["kind"] = "tensor-ndf";
  a["block"] = pack.block;
  a["precision"] = pack.precision;
  a["nonneg"] = pack.cp.nonneg;
  a["blank_threshold"] = pack.blank_threshold;
  a["exact_level_bytes"] = pack.exact_level_bytes;
  a["exact_min_level"] = pack.exact_min_level;
  a["lobes_per_tile"] = end.lobes_per_tile;
  a["max_error"] = end.max_error;
  a["error_target"] = end.error_target;
  a["rank"] = end.rank;
  a["flakes"] = flakes;
  return a;
}

void readTensorShardAssembly(const Json& a, tensor::TensorPackOptions* pack, TensorAssetEnd* end, bool* flakes) {
  auto field = [&](const char* key) -> const Json& {
    if (!a.is_object() || !a.contains(key)) throw Error(kExitInvalidInput, std::string("assembly lacks '") + key + "'");
    return a[key];
  };
  try {
    if (field("kind").get<std::string>() != "tensor-ndf")
      throw Error(kExitInvalidInput, "assembly of an unknown kind " + field("kind").dump());
    pack->block = field("block").get<int>();
    pack->precision = field("precision").get<int>();
    pack->cp.nonneg = field("nonneg").get<bool>();
    pack->blank_threshold = field("blank_threshold").get<double>();
    pack->exact_level_bytes = field("exact_level_bytes").get<uint64_t>();
    pack->exact_min_level = field("exact_min_level").get<int>();
    end->lobes_per_tile = field("lobes_per_tile").get<int>();
    end->max_error = field("max_error").get<double>();
    end->error_target = field("error_target").get<double>();
    end->rank = field("rank").get<int>();
    *flakes = field("flakes").get<bool>();
  } catch (const Json::exception&) {
    throw Error(kExitInvalidInput, "assembly fields of the wrong type");
  }
  if (pack->block < 1 || pack->block > int(format::kTensorMaxBlockBins) ||
      (pack->precision != 0 && pack->precision != 1) ||
      !(pack->blank_threshold >= 0.0 && pack->blank_threshold <= 1.0) || end->lobes_per_tile < 0 ||
      end->lobes_per_tile > bake::ndf::kMaxLobesPerTile || end->rank < 1)
    throw Error(kExitInvalidInput, "assembly fields out of range");
}

}  // namespace glintbake::cli
