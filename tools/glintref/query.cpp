// SPDX-License-Identifier: Apache-2.0
// Shared options, validation, loading and report fields of the glintref commands (query.h).
#include "query.h"

#include <glintbake/cli/ingest_options.h>
#include <glintbake/format/numbers.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace glintbake::glintref {
namespace {

std::string formatNumber(double v) {
  std::ostringstream out;
  out.precision(6);
  out << v;
  return out.str();
}

bool parseNumber(const std::string& text, double* value) {
  if (text.empty()) return false;
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return errno == 0 && end == text.c_str() + text.size() && std::isfinite(*value);
}

}  // namespace

void addQueryOptions(CLI::App& command, QueryOptions& options) {
  command.add_option("MAP", options.map, "Normal map (or height field with --height)")->required();
  command.add_option("--at", options.at_text, "Footprint centre X,Y in texels (texel centres at +0.5, y down)")
      ->required();
  command.add_option("--sigma", options.sigma, "Footprint standard deviation in texels (> 0)")->required();
  command.add_option("--sigma-r", options.sigma_r, "Intrinsic roughness: std of each flake's normal lobe, (0, 1)");
  command.add_option("--rate", options.rate, "Flakes per texel side (1..16)");
  cli::addIngestOptions(command, options.ingest);
}

void parsePair(const std::string& option, const std::string& text, double* a, double* b) {
  const size_t comma = text.find(',');
  if (comma == std::string::npos || !parseNumber(text.substr(0, comma), a) || !parseNumber(text.substr(comma + 1), b)) {
    throw cli::Error(cli::kExitBadArguments, option + " expects two finite numbers A,B; got '" + text + "'");
  }
}

Query loadQuery(cli::Tool& tool, const QueryOptions& options) {
  // Arguments first: a bad argument is reported as such even if the file is also bad.
  double x = 0.0, y = 0.0;
  parsePair("--at", options.at_text, &x, &y);
  if (std::fabs(x) > kMaxCentreTexels || std::fabs(y) > kMaxCentreTexels) {
    throw cli::Error(cli::kExitBadArguments, "--at " + options.at_text + " is farther than " +
                                                 formatNumber(kMaxCentreTexels) + " texels from the origin");
  }
  if (!(options.sigma > 0.0) || !std::isfinite(options.sigma)) {
    throw cli::Error(cli::kExitBadArguments,
                     "--sigma must be a positive number of texels, got " + formatNumber(options.sigma));
  }
  if (!(options.sigma_r > 0.0 && options.sigma_r < 1.0)) {
    throw cli::Error(cli::kExitBadArguments, "--sigma-r must be in (0, 1), got " + formatNumber(options.sigma_r));
  }
  if (options.rate < 1 || options.rate > reference::kMaxRate) {
    throw cli::Error(cli::kExitBadArguments, "--rate must be in 1.." + std::to_string(reference::kMaxRate) + ", got " +
                                                 std::to_string(options.rate));
  }
  // Flakes within the truncation disk (with their periodic images), before loading anything.
  const double step = 1.0 / options.rate;
  const double sigma_h = step * 1.5 / std::sqrt(12.0);
  const double radius = reference::kTruncationSigmas * std::sqrt(sigma_h * sigma_h + options.sigma * options.sigma);
  const double lobes = kPi * (radius * options.rate) * (radius * options.rate);
  if (lobes > kMaxLobes) {
    throw cli::Error(cli::kExitBadArguments, "--sigma " + formatNumber(options.sigma) + " at --rate " +
                                                 std::to_string(options.rate) + " sums about " + formatNumber(lobes) +
                                                 " flakes; the reference evaluator accepts at most " +
                                                 formatNumber(kMaxLobes) + " (reduce --sigma or --rate)");
  }

  Query query;
  const bake::NormalMap map = cli::loadNormalMapForTool(tool, options.map, options.ingest, &query.report);
  // The flakes take 80 bytes per flake: refuse maps whose flake set would not fit comfortably.
  const double flake_count = double(map.width) * map.height * options.rate * options.rate;
  if (flake_count > 4e8) {
    throw cli::Error(cli::kExitBadArguments, options.map + ": " + std::to_string(map.width) + "x" +
                                                 std::to_string(map.height) + " at --rate " +
                                                 std::to_string(options.rate) + " makes too many flakes (" +
                                                 formatNumber(flake_count) + ", at most 4e8)");
  }
  query.flakes = reference::buildFlakes(map, options.rate);
  query.footprint = {x, y, options.sigma};
  query.sigma_r = options.sigma_r;
  return query;
}

cli::Json queryJson(const QueryOptions& options, const Query& query, size_t lobes) {
  cli::Json doc;
  doc["map"] = {{"name", cli::baseName(options.map)},
                {"width", query.flakes.width},
                {"height", query.flakes.height},
                {"wrap", bake::wrapString(query.flakes.wrap)}};
  doc["footprint"] = {{"x", query.footprint.x}, {"y", query.footprint.y}, {"sigma", query.footprint.sigma}};
  doc["sigma_r"] = query.sigma_r;
  doc["rate"] = query.flakes.rate;
  doc["lobes"] = lobes;
  doc["ingest"] = cli::ingestReportJson(query.report);
  return doc;
}

}  // namespace glintbake::glintref
