// SPDX-License-Identifier: Apache-2.0
// ltcfit subcommands: each registers its options on a CLI11 subcommand and runs when selected.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/ltc/ltc.h>
#include <glintbake/bake/ltc/table.h>
#include <glintbake/bake/result.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/tool.h>

#include <string>

namespace glintbake::ltcfit {

struct TableArgs {
  std::string brdf = "ggx";
  int size = 64;
  int samples = 32;
  std::string method = "refined";
  int columns = 0;
  std::string output, exr_prefix, header;
};

struct EvalArgs {
  std::string table1, table2;
  std::string brdf = "ggx";
  int samples = 128;
  bool per_cell = false;
};

struct MultiscaleArgs {
  std::string output;
  int meso_points = 256;
  int grid = 9;
};

struct RoughnessArgs {
  std::string input, output, container;
  double alpha_micro = 0.1;
  bool exact_meso = false;
  bake::IngestOptions ingest;
};

int runTable(cli::Tool& tool, const TableArgs& args);
int runEval(cli::Tool& tool, const EvalArgs& args);
int runMultiscale(cli::Tool& tool, const MultiscaleArgs& args);
int runRoughness(cli::Tool& tool, const RoughnessArgs& args);

// Throw cli::Error with the error's exit code if a result failed (cli/exit_codes.h).
using cli::check;
using cli::unwrap;

}  // namespace glintbake::ltcfit
