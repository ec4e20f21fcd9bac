// glintref subcommands: the reference P-NDF of a normal map at one point (ndf), as a bin-averaged
// image (image) and as samples (sample). Each command registers its CLI11 subcommand and runs when
// selected; they share the map, footprint and flake options (query.h).
#pragma once

#include "query.h"

#include <glintbake/cli/tool.h>

#include <cstdint>
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
};

struct SampleOptions {
  QueryOptions query;
  uint64_t count = 0;
  uint64_t seed = 1;
  std::string output;  // .csv; empty: CSV on stdout (or the samples in the --json document)
};

CLI::App* addNdfCommand(CLI::App& app, NdfOptions& options);
CLI::App* addImageCommand(CLI::App& app, ImageOptions& options);
CLI::App* addSampleCommand(CLI::App& app, SampleOptions& options);

// Each returns a documented exit code or throws cli::Error.
int runNdf(cli::Tool& tool, NdfOptions& options);
int runImage(cli::Tool& tool, ImageOptions& options);
int runSample(cli::Tool& tool, SampleOptions& options);

}  // namespace glintbake::glintref
