// SPDX-License-Identifier: Apache-2.0
// ltcfit multiscale and ltcfit roughness.
#include "commands.h"

#include <glintbake/bake/ltc/multiscale.h>
#include <glintbake/bake/ltc/roughness.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/format/container.h>

#include <fstream>

namespace glintbake::ltcfit {

namespace {

cli::Json errorsJson(const bake::ltc::FitErrors& e) { return {{"rms", e.rms}, {"max", e.max}}; }

}  // namespace

int runMultiscale(cli::Tool& tool, const MultiscaleArgs& args) {
  const bake::ltc::MultiscaleFit fit = unwrap(bake::ltc::fitMultiscale(args.meso_points, args.grid));
  cli::Json doc = {{"tool", "ltcfit"},
                   {"command", "multiscale"},
                   {"meso",
                    {{"form", "alpha_me = y (p0 + p1 y + p2 y^2) / (1 + q0 y + q1 y^2), y = sqrt(1 - |b|)"},
                     {"coefficients", fit.meso.c},
                     {"points", fit.meso_points},
                     {"error", errorsJson(fit.meso_error)}}},
                   {"combine",
                    {{"form", "alpha = a_mi + a_me + a_mi a_me (k0 + k1 a_mi + k2 a_me)"},
                     {"coefficients", fit.combine.k},
                     {"grid", fit.combine_grid},
                     {"error", errorsJson(fit.combine_error)},
                     {"paper_form", "alpha = 0.07 a_mi^2 + 0.94 a_mi + a_me - 0.83 a_mi a_me (Tao et al. 2021, eq. 7)"},
                     {"paper_error", errorsJson(fit.combine_paper_error)}}}};
  cli::writeOutputFile(args.output, doc.dump(2) + "\n");
  tool.addOutput(args.output);
  if (tool.common().json) tool.printJson(doc);
  return cli::kExitOk;
}

int runRoughness(cli::Tool& tool, const RoughnessArgs& args) {
  bake::IngestReport report;
  const bake::NormalMap map = cli::loadNormalMapForTool(tool, args.input, args.ingest, &report);
  bake::ltc::RoughnessOptions options;
  options.alpha_micro = args.alpha_micro;
  options.exact_meso = args.exact_meso;
  const auto levels = unwrap(bake::ltc::bakeRoughness(map, options));

  cli::Json parameters = {{"alpha_micro", args.alpha_micro},
                          {"exact_meso", args.exact_meso},
                          {"filter", "box2x2"},
                          {"ingest", cli::ingestOptionsJson(args.ingest)}};
  if (!args.container.empty()) {
    cli::Json metadata = tool.makeMetadata(format::AssetKind::kRoughness, parameters);
    metadata["asset"] = {{"width", map.width},
                         {"height", map.height},
                         {"levels", int(levels.size())},
                         {"alpha_micro", args.alpha_micro},
                         {"quantity", "overall GGX alpha per texel (Tao et al. 2021)"},
                         {"section", {{"type", format::kSectionRoughness}, {"key", "mip level"}}}};
    cli::ContainerOutput out(tool, args.container, format::AssetKind::kRoughness);
    check(bake::ltc::writeRoughnessSections(levels, out.writer()));
    out.finish(metadata);
  }
  const bake::BakeStatus status = bake::ltc::writeRoughnessExr(levels, args.output);
  if (!status.ok()) {
    if (!args.container.empty()) std::remove(args.container.c_str());
    check(status);
  }
  tool.addOutput(args.output);

  if (tool.common().json) {
    cli::Json mips = cli::Json::array();
    for (const auto& level : levels) {
      double sum = 0.0, lo = 1.0, hi = 0.0;
      for (float a : level.alpha) sum += a, lo = std::min(lo, double(a)), hi = std::max(hi, double(a));
      mips.push_back({{"width", level.width},
                      {"height", level.height},
                      {"mean_alpha", sum / double(level.alpha.size())},
                      {"min_alpha", lo},
                      {"max_alpha", hi}});
    }
    tool.printJson({{"tool", "ltcfit"},
                    {"command", "roughness"},
                    {"input", cli::baseName(args.input)},
                    {"alpha_micro", args.alpha_micro},
                    {"levels", mips},
                    {"ingest", cli::ingestReportJson(report)}});
  }
  return cli::kExitOk;
}

}  // namespace glintbake::ltcfit
