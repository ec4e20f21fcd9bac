// SPDX-License-Identifier: Apache-2.0
// glintinfo subcommands: inspect (info), check (validate), compare (diff) and extract (export)
// glintbake containers, and join the shards of a sharded bake (merge). Each command registers its CLI11 subcommand and runs when selected.
#pragma once

#include <glintbake/cli/tool.h>

#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::glintinfo {

struct InfoOptions {
  std::string file;
};

struct ValidateOptions {
  std::string file;
};

struct DiffOptions {
  std::string file_a, file_b;
  double rel_tol = 1e-6;  // relative L2 difference below which image sections are the same
  double abs_tol = 0.0;   // maximum absolute difference below which image sections are the same
};

struct ExportOptions {
  std::string file;
  std::string section;  // index ("3") or "type:key" ("ndf-chunk:4294967296", "17:0")
  uint32_t layer = 0;
  int channel = -1;            // -1: every channel
  std::string output;          // .exr, .png, .tif, ...
  std::string scale = "auto";  // PNG only: divide by this ("auto" = maximum exported value)
};

struct MergeOptions {
  std::vector<std::string> parts;
  std::string output;
};

CLI::App* addInfoCommand(CLI::App& app, InfoOptions& options);
CLI::App* addValidateCommand(CLI::App& app, ValidateOptions& options);
CLI::App* addDiffCommand(CLI::App& app, DiffOptions& options);
CLI::App* addExportCommand(CLI::App& app, ExportOptions& options);
CLI::App* addMergeCommand(CLI::App& app, MergeOptions& options);

// Each returns a documented exit code or throws cli::Error.
int runInfo(cli::Tool& tool, const InfoOptions& options);
int runValidate(cli::Tool& tool, const ValidateOptions& options);
int runDiff(cli::Tool& tool, const DiffOptions& options);
int runExport(cli::Tool& tool, const ExportOptions& options);
int runMerge(cli::Tool& tool, const MergeOptions& options);

}  // namespace glintbake::glintinfo
