// SPDX-License-Identifier: Apache-2.0
// The procedural-surface options of the tools that bake a pyramid (ndfgen, tensorpack), with the
// same names and defaults: --procedural glitter, --particles, --alpha, --distribution, --glitter-seed,
// --size, --gamma. A procedural surface replaces the normal map as the source of the NDF images
// (libbake/glitter; formats/SPEC.md 10.6).
#pragma once

#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/cli/tool.h>

#include <cstdint>
#include <string>

namespace glintbake::cli {

struct GlitterCliOptions {
  std::string procedural;  // "" (a normal map) or "glitter"
  int64_t particles = 1000000;
  double alpha = 0.2;
  std::string distribution = "beckmann";
  uint64_t seed = 1;
  std::string size_text = "256,256";  // --size W,H texels
  double gamma_deg = 1.0;
};

void addGlitterOptions(CLI::App& app, GlitterCliOptions& options);

// The validated parameters (Error exit 1 with a one-line message naming the option).
bake::glitter::GlitterParams resolveGlitterOptions(const GlitterCliOptions& options, int ndf_res);

// Canonical JSON of the parameters (metadata and --json).
Json glitterParamsJson(const bake::glitter::GlitterParams& params);

}  // namespace glintbake::cli
