// SPDX-License-Identifier: Apache-2.0
// ltcfit: LTC tables for area lights (Heitz et al. 2016), their fit error, multi-scale roughness
// relations (Tao et al. 2021) and per-normal-map roughness mips.
#include "commands.h"

#include <glintbake/cli/embed.h>
#include <glintbake/cli/ingest_options.h>

#include <glintbake/format/container.h>

#include <cstring>

namespace glintbake::ltcfit {}  // namespace glintbake::ltcfit

int glintbake::cli::ltcfitMain(int argc, char** argv) {
  using namespace glintbake;
  cli::Tool tool("ltcfit", "Fits LTC tables for area lights and bakes multi-scale roughness");
  tool.addExample("ltcfit table --brdf ggx --size 64 -o ggx.gbk", "Fit a 64 x 64 GGX table for area lights.");
  tool.addExample("ltcfit roughness map.png -o map-rough.exr", "Bake the per-texel roughness mips of a normal map (mipmapped EXR).");
  CLI::App& app = tool.app();
  app.require_subcommand(1);

  ltcfit::TableArgs table;
  CLI::App* table_cmd = app.add_subcommand("table", "Fit an LTC table (container, optional EXR pair and C header)");
  table_cmd->fallthrough();
  table_cmd->add_option("--brdf", table.brdf, "BRDF to fit")->check(CLI::IsMember({"ggx", "beckmann"}));
  table_cmd->add_option("--size", table.size, "Table size N (N x N cells)")->check(CLI::Range(2, 256));
  table_cmd->add_option("--samples", table.samples, "Stratified samples per axis in the fit")
      ->check(CLI::Range(4, 256));
  table_cmd->add_option("--method", table.method, "refined (default) or published (100 Nelder-Mead iterations)")
      ->check(CLI::IsMember({"refined", "published"}));
  table_cmd
      ->add_option("--columns", table.columns,
                   "Fit only this many roughness columns from the roughest down (0 = all; for quick checks)")
      ->check(CLI::Range(0, 256));
  table_cmd->add_option("-o,--output", table.output, "Output container (kind ltc-table)")->required();
  table_cmd->add_option("--exr", table.exr_prefix, "Also write PREFIX_1.exr and PREFIX_2.exr (published layout)");
  table_cmd->add_option("--header", table.header, "Also write a C header with the same numbers");

  ltcfit::EvalArgs eval;
  CLI::App* eval_cmd = app.add_subcommand("eval", "Fit error of a table in the published layout");
  eval_cmd->fallthrough();
  eval_cmd->add_option("table1", eval.table1, "ltc_1 image (RGBA)")->required();
  eval_cmd->add_option("table2", eval.table2, "ltc_2 image (RGBA)")->required();
  eval_cmd->add_option("--brdf", eval.brdf, "BRDF the table approximates")->check(CLI::IsMember({"ggx", "beckmann"}));
  eval_cmd->add_option("--samples", eval.samples, "Stratified samples per axis and strategy")
      ->check(CLI::Range(4, 1024));
  eval_cmd->add_flag("--per-cell", eval.per_cell, "Include every cell's error in the --json output");

  ltcfit::MultiscaleArgs multiscale;
  CLI::App* ms_cmd = app.add_subcommand("multiscale", "Refit the multi-scale roughness relations of Tao et al. 2021");
  ms_cmd->fallthrough();
  ms_cmd->add_option("-o,--output", multiscale.output, "Coefficients and errors as JSON")->required();
  ms_cmd->add_option("--meso-points", multiscale.meso_points, "Ground-truth points of alpha_me(|b|)")
      ->check(CLI::Range(8, 100000));
  ms_cmd->add_option("--grid", multiscale.grid, "Grid points per axis of the (alpha_mi, alpha_me) convolution")
      ->check(CLI::Range(3, 64));

  ltcfit::RoughnessArgs rough;
  CLI::App* rough_cmd = app.add_subcommand("roughness", "Bake per-texel roughness mips of a normal map");
  rough_cmd->fallthrough();
  rough_cmd->add_option("map", rough.input, "Normal map")->required();
  rough_cmd->add_option("--alpha-micro", rough.alpha_micro, "Micro-scale GGX alpha")
      ->required()
      ->check(CLI::Range(0.0, 1.0));
  rough_cmd->add_option("-o,--output", rough.output, "Mipmapped single-channel EXR")->required();
  rough_cmd->add_option("--container", rough.container, "Also write a container (kind roughness)");
  rough_cmd->add_flag("--exact-meso", rough.exact_meso, "Invert eq. 4 exactly instead of the rational fit");
  cli::addIngestOptions(*rough_cmd, rough.ingest);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    if (table_cmd->parsed()) return ltcfit::runTable(t, table);
    if (eval_cmd->parsed()) return ltcfit::runEval(t, eval);
    if (ms_cmd->parsed()) return ltcfit::runMultiscale(t, multiscale);
    return ltcfit::runRoughness(t, rough);
  });
}
