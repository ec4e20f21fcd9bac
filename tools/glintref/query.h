// SPDX-License-Identifier: Apache-2.0
// What every glintref command evaluates: a normal map, its flakes at a sub-sampling rate, a
// Gaussian footprint and the intrinsic roughness. Parsing, validation (exit code 1 with a one-line
// message) and the shared parts of the --json reports.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/cli/tool.h>
#include <glintbake/reference/pndf.h>

#include <string>

namespace glintbake::glintref {

struct QueryOptions {
  std::string map;
  std::string at_text;  // --at X,Y in texels
  double sigma = 0.0;   // --sigma, footprint std in texels
  double sigma_r = reference::kDefaultSigmaR;
  int rate = 1;
  bake::IngestOptions ingest;
};

// Footprint centres farther than this from the origin (texels) are refused as a likely mistake.
constexpr double kMaxCentreTexels = 1e7;
// Largest number of flakes (with their periodic images) one footprint may sum: bounds memory
// (64 bytes per lobe for images and samples) and time.
constexpr double kMaxLobes = 2e7;

// Registers MAP, --at, --sigma, --sigma-r, --rate and the ingest options on a subcommand.
void addQueryOptions(CLI::App& command, QueryOptions& options);

// Parses "A,B" into two finite numbers; throws cli::Error(kExitBadArguments) naming the option.
void parsePair(const std::string& option, const std::string& text, double* a, double* b);

// A loaded query: the map's flakes and the validated footprint.
struct Query {
  reference::FlakeSet flakes;
  reference::Footprint footprint;
  double sigma_r = 0.0;
  bake::IngestReport report;
};

// Validates the options (before touching the file), loads the map through the shared ingest and
// builds its flakes. Throws cli::Error with the documented exit code.
Query loadQuery(cli::Tool& tool, const QueryOptions& options);

// The parts of every --json report that describe the query: map name (never a path), size, wrap,
// footprint, sigma_r, rate, the number of lobes summed and the ingest report.
cli::Json queryJson(const QueryOptions& options, const Query& query, size_t lobes);

}  // namespace glintbake::glintref
