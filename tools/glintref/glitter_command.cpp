// SPDX-License-Identifier: Apache-2.0
// glintref glitter: the discrete microfacet NDF of a procedural glitter surface (Jakob et al.
// 2014; formats/SPEC.md 10.6) for one uv box and one direction cone, by the counting hierarchy
// with the paper's split rule for this query, or by explicit enumeration of every facet.
#include "commands.h"

#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/format/kinds/glitter_model.h>
#include <glintbake/format/numbers.h>
#include <glintbake/reference/glitter.h>

#include <chrono>
#include <cmath>
#include <cstdio>

namespace glintbake::glintref {
namespace {

constexpr uint64_t kMaxEnumerated = 20000000;

}  // namespace

CLI::App* addGlitterCommand(CLI::App& app, GlitterOptions& o) {
  CLI::App* cmd =
      app.add_subcommand("glitter", "Discrete microfacet NDF of a procedural glitter surface in a uv box and a cone");
  cmd->add_option("--particles", o.particles, "Facets N on the unit uv square (1..2^40)")->required();
  cmd->add_option("--alpha", o.alpha, "Roughness of the smooth NDF (0.001..4)")->required();
  cmd->add_option("--distribution", o.distribution, "beckmann or ggx")->capture_default_str();
  cmd->add_option("--seed", o.seed, "Realisation")->capture_default_str();
  cmd->add_option("--at", o.at_text, "Centre U,V of the uv box (the unit square repeats)")->required();
  cmd->add_option("--extent", o.extent, "Side of the uv box, (0, 1]")->required();
  cmd->add_option("--s", o.s_text, "Cone axis as an s-plane point SX,SY (|s| < 1)")->required();
  cmd->add_option("--gamma", o.gamma_deg, "Cone half-angle, degrees (0..28.6)")->capture_default_str();
  cmd->add_option("--max-depth", o.max_depth, "Levels of the uv and direction hierarchies (1..20)")
      ->capture_default_str();
  cmd->add_flag("--exact", o.exact, "No binomial early stop: integer counts");
  cmd->add_flag("--enumerate", o.enumerate, "Also count by explicit enumeration of every facet (N <= 2e7)");
  return cmd;
}

int runGlitter(cli::Tool& tool, GlitterOptions& o) {
  double u = 0.0, v = 0.0, sx = 0.0, sy = 0.0;
  parsePair("--at", o.at_text, &u, &v);
  parsePair("--s", o.s_text, &sx, &sy);
  if (!(std::isfinite(u) && std::isfinite(v))) throw cli::Error(cli::kExitBadArguments, "--at must be finite");
  if (!(o.extent > 0.0 && o.extent <= 1.0)) throw cli::Error(cli::kExitBadArguments, "--extent must be in (0, 1]");
  if (!(sx * sx + sy * sy < 1.0)) throw cli::Error(cli::kExitBadArguments, "--s must lie inside the unit disk");
  bake::glitter::GlitterParams p;
  if (o.particles <= 0) throw cli::Error(cli::kExitBadArguments, "--particles must be in [1, 2^40]");
  p.particles = uint64_t(o.particles);
  p.alpha = o.alpha;
  p.seed = o.seed;
  p.max_depth = o.max_depth;
  p.gamma = o.gamma_deg * kPi / 180.0;
  if (o.distribution == "beckmann") {
    p.distribution = format::GlitterDistribution::kBeckmann;
  } else if (o.distribution == "ggx") {
    p.distribution = format::GlitterDistribution::kGgx;
  } else {
    throw cli::Error(cli::kExitBadArguments, "--distribution must be beckmann or ggx");
  }
  cli::check(bake::glitter::validateGlitterParams(p));
  if (o.enumerate && p.particles > kMaxEnumerated)
    throw cli::Error(cli::kExitBadArguments, "--enumerate needs --particles <= 20000000");

  const auto t0 = std::chrono::steady_clock::now();
  bake::glitter::GlitterModel model(p);
  const double table_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const format::GlitterUvRegion uv = format::GlitterUvRegion::box(u, v, o.extent, o.extent);
  const format::GlitterVec3 axis{sx, sy, std::sqrt(1.0 - sx * sx - sy * sy)};
  const format::GlitterDirRegion cone = format::GlitterDirRegion::cone(axis, p.gamma);
  const double cone_sr = 2.0 * kPi * (1.0 - std::cos(p.gamma));
  // The paper's rule with this query's own size.
  const format::GlitterTreeShape shape{uv.area, cone_sr};
  format::GlitterCountOptions copt;
  copt.early_stop = !o.exact;
  format::GlitterCountStats stats;
  const auto t1 = std::chrono::steady_clock::now();
  const double count = format::glitterCount(model.view(), shape, uv, cone, copt, &stats);
  const double query_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  const double d = count / (uv.area * cone_sr * double(p.particles));
  const double smooth = reference::smoothGlitterCone(p.distribution, p.alpha, axis, p.gamma);
  double enumerated = -1.0;
  if (o.enumerate) {
    const auto facets = reference::enumerateGlitterFacets(model.view(), shape);
    enumerated = double(reference::countGlitterFacets(facets, uv, cone));
  }

  if (tool.common().json) {
    cli::Json doc;
    doc["tool"] = "glintref";
    doc["command"] = "glitter";
    doc["particles"] = p.particles;
    doc["alpha"] = p.alpha;
    doc["distribution"] = o.distribution;
    doc["seed"] = p.seed;
    doc["max_depth"] = p.max_depth;
    doc["at"] = {u, v};
    doc["extent"] = o.extent;
    doc["uv_area"] = uv.area;
    doc["s"] = {sx, sy};
    doc["gamma_degrees"] = o.gamma_deg;
    doc["cone_solid_angle"] = cone_sr;
    doc["early_stop"] = copt.early_stop;
    doc["count"] = count;
    doc["expected_count"] = smooth * uv.area * cone_sr * double(p.particles);
    doc["D"] = d;
    doc["D_s"] = d / axis.z;
    doc["smooth_D"] = smooth;
    doc["nodes"] = stats.nodes;
    doc["facets_tested"] = stats.facets;
    doc["integral_entries"] = model.integrals().size();
    doc["query_seconds"] = query_seconds;
    doc["table_seconds"] = table_seconds;
    doc["enumerated_count"] = enumerated < 0 ? cli::Json(nullptr) : cli::Json(enumerated);
    tool.printJson(doc);
  } else {
    std::printf("count %.17g  D %.17g  smooth %.17g\n", count, d, smooth);
    if (enumerated >= 0) std::printf("enumerated %.17g\n", enumerated);
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintref
