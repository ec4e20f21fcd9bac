// SPDX-License-Identifier: Apache-2.0
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/glitter_options.h>
#include <glintbake/format/numbers.h>

#include <cmath>
#include <cstdio>

namespace glintbake::cli {

void addGlitterOptions(CLI::App& app, GlitterCliOptions& o) {
  app.add_option("--procedural", o.procedural, "Bake a procedural surface instead of a map: glitter");
  app.add_option("--particles", o.particles, "glitter: facets N on the surface (1..2^40)")->capture_default_str();
  app.add_option("--alpha", o.alpha, "glitter: roughness of the smooth NDF (0.001..4)")->capture_default_str();
  app.add_option("--distribution", o.distribution, "glitter: beckmann or ggx")->capture_default_str();
  app.add_option("--glitter-seed", o.seed, "glitter: realisation")->capture_default_str();
  app.add_option("--size", o.size_text, "glitter: surface size W,H in texels (1..65536)")->capture_default_str();
  app.add_option("--gamma", o.gamma_deg, "glitter: cone half-angle of point queries, degrees (0..28.6)")
      ->capture_default_str();
}

bake::glitter::GlitterParams resolveGlitterOptions(const GlitterCliOptions& o, int ndf_res) {
  if (o.procedural != "glitter") throw Error(kExitBadArguments, "--procedural must be glitter");
  bake::glitter::GlitterParams p;
  if (o.particles <= 0) throw Error(kExitBadArguments, "--particles must be in [1, 2^40]");
  p.particles = uint64_t(o.particles);
  p.alpha = o.alpha;
  p.seed = o.seed;
  p.gamma = o.gamma_deg * kPi / 180.0;
  p.ndf_res = ndf_res;
  if (o.distribution == "beckmann") {
    p.distribution = format::GlitterDistribution::kBeckmann;
  } else if (o.distribution == "ggx") {
    p.distribution = format::GlitterDistribution::kGgx;
  } else {
    throw Error(kExitBadArguments, "--distribution must be beckmann or ggx");
  }
  long long w = 0, h = 0;
  char tail = 0;
  if (std::sscanf(o.size_text.c_str(), "%lld,%lld%c", &w, &h, &tail) != 2 || w < 1 || h < 1 || w > 65536 || h > 65536)
    throw Error(kExitBadArguments, "--size must be W,H with 1 <= W, H <= 65536 (got '" + o.size_text + "')");
  p.map_width = int(w);
  p.map_height = int(h);
  check(bake::glitter::validateGlitterParams(p));
  return p;
}

Json glitterParamsJson(const bake::glitter::GlitterParams& p) {
  Json j;
  j["procedural"] = "glitter";
  j["particles"] = p.particles;
  j["alpha"] = p.alpha;
  j["distribution"] = format::glitterDistributionString(p.distribution);
  j["seed"] = p.seed;
  j["size"] = {p.map_width, p.map_height};
  j["gamma"] = p.gamma;
  j["max_depth"] = p.max_depth;
  return j;
}

}  // namespace glintbake::cli
