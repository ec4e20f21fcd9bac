// SPDX-License-Identifier: Apache-2.0
// Opening the asset and parsing the footprint options shared by the glintquery commands.
#include "commands.h"

#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/stdin_input.h>
#include <glintbake/format/container.h>

#include <cmath>
#include <stdexcept>

namespace glintbake::glintquery {

using cli::Error;

// Parses "A,B" into two finite numbers.
void parsePair(const std::string& text, const char* option, double* a, double* b) {
  const size_t comma = text.find(',');
  bool ok = comma != std::string::npos;
  if (ok) {
    try {
      size_t ua = 0, ub = 0;
      const std::string sa = text.substr(0, comma), sb = text.substr(comma + 1);
      *a = std::stod(sa, &ua);
      *b = std::stod(sb, &ub);
      ok = ua == sa.size() && ub == sb.size() && std::isfinite(*a) && std::isfinite(*b);
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok) throw Error(cli::kExitBadArguments, std::string(option) + " expects two numbers A,B (got '" + text + "')");
}

Asset openAsset(cli::Tool& tool, const std::string& argument) {
  const std::string path = cli::resolveInput(argument);
  tool.addInput(path);
  Asset asset;
  const runtime::RuntimeStatus s = runtime::openNdfAsset(path.c_str(), &asset.source);
  if (s == runtime::RuntimeStatus::kOk) {
    asset.kind = glintbake::format::assetKindString(asset.source->kind());
    return asset;
  }
  throw Error(cli::exitCodeOf(s), "cannot open " + path + ": " + runtime::statusString(s));
}

void addFootprintOptions(CLI::App* cmd, FootprintOptions& options) {
  cmd->add_option("asset", options.asset, "NDF asset (.gbk)")->required();
  cmd->add_option("--at", options.at_text, "Footprint centre X,Y in texels")->required();
  cmd->add_option("--sigma", options.sigma, "Footprint std in texels (>= 0)")->required();
}

runtime::Footprint parseFootprint(const FootprintOptions& options) {
  runtime::Footprint fp;
  parsePair(options.at_text, "--at", &fp.x, &fp.y);
  if (!(options.sigma >= 0.0) || !std::isfinite(options.sigma))
    throw Error(cli::kExitBadArguments, "--sigma must be >= 0");
  fp.sigma = options.sigma;
  return fp;
}

void checkQuery(runtime::RuntimeStatus s, const char* what) {
  if (s != runtime::RuntimeStatus::kOk)
    throw Error(cli::kExitBadArguments, std::string(what) + ": " + runtime::statusString(s));
}

}  // namespace glintbake::glintquery
