// SPDX-License-Identifier: Apache-2.0
// glintquery subcommands: P-NDF queries on a baked NDF asset through the runtime (point, image,
// batch). Each command registers its CLI11 subcommand and runs when selected.
#pragma once

#include <glintbake/cli/tool.h>
#include <glintbake/runtime/ndf_source.h>

#include <memory>
#include <string>

namespace glintbake::glintquery {

// The footprint every command queries: centre --at X,Y and --sigma, texels.
struct FootprintOptions {
  std::string asset;    // NDF asset (.gbk)
  std::string at_text;  // "X,Y"
  double sigma = 1.0;
};

struct PointOptions {
  FootprintOptions footprint;
  std::string s_text;  // "SX,SY"
};

struct ImageOptions {
  FootprintOptions footprint;
  std::string output;
  double png_scale = 0.0;      // 0: 1 for float formats, 1/max for integer formats
  std::string preview;         // a PNG beside the output
  double preview_scale = 0.0;  // 0: 1/max
};

struct BatchOptions {
  std::string asset;
};

struct MaterialiseOptions {
  std::string asset;
  std::string cells;  // "I0,J0,NX,NY"
  std::string output;
};

CLI::App* addPointCommand(CLI::App& app, PointOptions& options);
CLI::App* addImageCommand(CLI::App& app, ImageOptions& options);
CLI::App* addBatchCommand(CLI::App& app, BatchOptions& options);
CLI::App* addMaterialiseCommand(CLI::App& app, MaterialiseOptions& options);

// Each returns a documented exit code or throws cli::Error.
int runPoint(cli::Tool& tool, const PointOptions& options);
int runImage(cli::Tool& tool, const ImageOptions& options);
int runBatch(cli::Tool& tool, const BatchOptions& options);
int runMaterialise(cli::Tool& tool, const MaterialiseOptions& options);

// Shared by the commands (asset.cpp).
// An opened NDF asset of any kind the runtime reads, opened once.
struct Asset {
  std::unique_ptr<runtime::NdfSource> source;
  std::string kind;  // "ndf-pyramid", "tensor-ndf"
};
Asset openAsset(cli::Tool& tool, const std::string& path);
// Parses "A,B" into two finite numbers; kExitBadArguments naming the option otherwise.
void parsePair(const std::string& text, const char* option, double* a, double* b);
// Registers the asset and --at, --sigma.
void addFootprintOptions(CLI::App* cmd, FootprintOptions& options);
// Checks --at and --sigma; the footprint they give.
runtime::Footprint parseFootprint(const FootprintOptions& options);
// kExitBadArguments naming the query when a runtime query failed.
void checkQuery(runtime::RuntimeStatus status, const char* what);

}  // namespace glintbake::glintquery
