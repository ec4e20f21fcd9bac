// SPDX-License-Identifier: Apache-2.0
// glintquery point: the P-NDF value at one s-plane point.
#include "commands.h"

#include <iostream>
#include <sstream>

namespace glintbake::glintquery {

namespace rt = glintbake::runtime;
using cli::Json;

CLI::App* addPointCommand(CLI::App& app, PointOptions& options) {
  CLI::App* point = app.add_subcommand("point", "P-NDF value at one s-plane point");
  addFootprintOptions(point, options.footprint);
  point->add_option("--s", options.s_text, "s-plane point SX,SY")->required();
  return point;
}

int runPoint(cli::Tool& tool, const PointOptions& options) {
  double x, y, sx, sy;
  parsePair(options.footprint.at_text, "--at", &x, &y);
  parsePair(options.s_text, "--s", &sx, &sy);
  const rt::Footprint fp = parseFootprint(options.footprint);
  const Asset ndf = openAsset(tool, options.footprint.asset);
  double v = 0.0;
  checkQuery(ndf.source->eval(fp, rt::SPoint{sx, sy}, &v), "point query");
  if (tool.common().json) {
    Json doc;
    doc["tool"] = "glintquery";
    doc["op"] = "point";
    doc["asset"] = cli::baseName(options.footprint.asset);
    doc["kind"] = ndf.kind;
    doc["at"] = {x, y};
    doc["sigma"] = fp.sigma;
    doc["s"] = {sx, sy};
    doc["value"] = v;
    tool.printJson(doc);
  } else {
    std::ostringstream os;
    os.precision(9);
    os << v << "\n";
    std::cout << os.str();
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintquery
