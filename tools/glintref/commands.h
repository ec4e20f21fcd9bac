// SPDX-License-Identifier: Apache-2.0
// glintref subcommands: the reference P-NDF of a normal map at one point (ndf), as a bin-averaged
// image (image) and as samples (sample); a renderer of scenes with that P-NDF, a baked asset or a
// smooth BRDF (render), and image comparison (compare). Each command registers its CLI11 subcommand and runs when
// selected; they share the map, footprint and flake options (query.h).
#pragma once

#include "query.h"

#include <glintbake/cli/tool.h>

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/render/image_compare.h>

#include <cstdint>
#include <limits>
#include <string>

namespace glintbake::glintref {

struct NdfOptions {
  QueryOptions query;
  std::string s_text;  // --s SX,SY
};

struct ImageOptions {
  QueryOptions query;
  int res = 128;
  std::string output;
  std::string preview;  // an 8-bit PNG scaled by the maximum, beside the output
};

struct SampleOptions {
  QueryOptions query;
  uint64_t count = 0;
  uint64_t seed = 1;
  std::string output;  // .csv; empty: CSV on stdout (or the samples in the --json document)
};

struct RenderOptions {
  std::string scene;
  std::string output;
  std::string ndf = "smooth";
  int spp = 16;
  uint64_t seed = 1;
  std::string env = "prefilter";
  std::string ltc;         // LTC table for polygon lights (smooth mode)
  std::string asset;       // overrides material.asset
  std::string normal_map;  // overrides material.normal_map
  std::string image_size;  // --image-size W,H; empty: the scene's
  std::string preview;     // tone-mapped PNG
  double exposure = 1.0;
  std::string compare;  // --compare REFERENCE: the metrics of glintref compare against it
  std::string heatmap;  // with --compare: its heat map PNG
  double heatmap_scale = 0.0;
  bake::IngestOptions ingest;
};

struct CompareOptions {
  std::string image;
  std::string reference;
  std::string heatmap;
  double heatmap_scale = 0.0;
  double max_rel_mse = std::numeric_limits<double>::infinity();
};

struct GlitterOptions {
  int64_t particles = 0;
  double alpha = 0.0;
  std::string distribution = "beckmann";
  uint64_t seed = 1;
  std::string at_text;  // --at U,V
  double extent = 0.0;
  std::string s_text;  // --s SX,SY
  double gamma_deg = 1.0;
  int max_depth = 20;
  bool exact = false;
  bool enumerate = false;
};

CLI::App* addNdfCommand(CLI::App& app, NdfOptions& options);
CLI::App* addGlitterCommand(CLI::App& app, GlitterOptions& options);
CLI::App* addImageCommand(CLI::App& app, ImageOptions& options);
CLI::App* addSampleCommand(CLI::App& app, SampleOptions& options);
CLI::App* addRenderCommand(CLI::App& app, RenderOptions& options);
CLI::App* addCompareCommand(CLI::App& app, CompareOptions& options);

// Each returns a documented exit code or throws cli::Error.
int runNdf(cli::Tool& tool, NdfOptions& options);
int runGlitter(cli::Tool& tool, GlitterOptions& options);
int runImage(cli::Tool& tool, ImageOptions& options);
int runSample(cli::Tool& tool, SampleOptions& options);
int runRender(cli::Tool& tool, RenderOptions& options);
int runCompare(cli::Tool& tool, CompareOptions& options);

// What compare and render --compare share. checkHeatmap: the heat map's scale, and its path (a .png
// in an existing folder; empty for none). loadCompareImage: an image read for comparison (its read
// error thrown). compareLoaded: the metrics of `image` against `reference`, the heat map written
// when `heatmap` is not empty. comparisonJson: compare's JSON fields of them.
void checkHeatmap(const std::string& heatmap, double heatmap_scale, const char* option);
bake::render::RgbImage loadCompareImage(const std::string& path);
bake::render::CompareMetrics compareLoaded(cli::Tool& tool, const bake::render::RgbImage& image,
                                           const bake::render::RgbImage& reference, const std::string& heatmap,
                                           double heatmap_scale);
cli::Json comparisonJson(const bake::render::CompareMetrics& m, const std::string& heatmap);

}  // namespace glintbake::glintref
