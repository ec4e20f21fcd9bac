// SPDX-License-Identifier: Apache-2.0
// glintinfo: inspects, validates, compares and exports glintbake containers, and merges shards.
#include "commands.h"

int main(int argc, char** argv) {
  using namespace glintbake;
  cli::Tool tool("glintinfo", "Inspects, validates, compares and exports glintbake containers (.gbk)");
  tool.addExample("glintinfo info brushed.gbk", "Print the header, the sections and the metadata of an asset.");
  tool.addExample("glintinfo validate --json brushed.gbk",
                  "Check every rule of the specification; messages with stable ids as JSON.");
  tool.addExample("glintinfo diff old.gbk new.gbk",
                  "Compare two containers section by section (exit code 7 when they differ).");
  CLI::App& app = tool.app();
  // Common options (--json, --quiet, ...) may follow the subcommand.
  app.fallthrough();
  app.require_subcommand(0, 1);

  glintinfo::InfoOptions info;
  glintinfo::ValidateOptions validate;
  glintinfo::DiffOptions diff;
  glintinfo::ExportOptions exported;
  glintinfo::MergeOptions merge;
  CLI::App* info_cmd = glintinfo::addInfoCommand(app, info);
  CLI::App* validate_cmd = glintinfo::addValidateCommand(app, validate);
  CLI::App* diff_cmd = glintinfo::addDiffCommand(app, diff);
  CLI::App* export_cmd = glintinfo::addExportCommand(app, exported);
  CLI::App* merge_cmd = glintinfo::addMergeCommand(app, merge);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    if (info_cmd->parsed()) return glintinfo::runInfo(t, info);
    if (validate_cmd->parsed()) return glintinfo::runValidate(t, validate);
    if (diff_cmd->parsed()) return glintinfo::runDiff(t, diff);
    if (export_cmd->parsed()) return glintinfo::runExport(t, exported);
    if (merge_cmd->parsed()) return glintinfo::runMerge(t, merge);
    throw cli::Error(cli::kExitBadArguments,
                     "no command given: use info, validate, diff, export or merge (see --help)");
  });
}
