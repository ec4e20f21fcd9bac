// SPDX-License-Identifier: Apache-2.0
// glintref ndf: the reference P-NDF D(s) at one point of the s-plane.
#include "commands.h"

#include <glintbake/reference/pndf.h>

#include <cstdio>

namespace glintbake::glintref {

CLI::App* addNdfCommand(CLI::App& app, NdfOptions& options) {
  CLI::App* cmd = app.add_subcommand("ndf", "Evaluate the P-NDF D(s) of a footprint at one s-plane point");
  addQueryOptions(*cmd, options.query);
  cmd->add_option("--s", options.s_text, "s-plane point SX,SY (projected normal: x right, y up)")->required();
  return cmd;
}

int runNdf(cli::Tool& tool, NdfOptions& options) {
  double sx = 0.0, sy = 0.0;
  parsePair("--s", options.s_text, &sx, &sy);
  const Query query = loadQuery(tool, options.query);

  const double value = reference::evalPndf(query.flakes, query.footprint, sx, sy, query.sigma_r);
  const size_t lobes = reference::footprintLobes(query.flakes, query.footprint, query.sigma_r).size();
  const double weight = reference::footprintWeight(query.flakes, query.footprint);

  if (tool.common().json) {
    cli::Json doc;
    doc["tool"] = "glintref";
    doc["command"] = "ndf";
    doc.update(queryJson(options.query, query, lobes));
    doc["s"] = {sx, sy};
    doc["value"] = value;
    doc["total_weight"] = weight;
    tool.printJson(doc);
  } else {
    std::printf("%.17g\n", value);
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintref
