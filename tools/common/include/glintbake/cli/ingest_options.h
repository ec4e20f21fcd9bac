// SPDX-License-Identifier: Apache-2.0
// The normal-map ingest options every tool that reads a normal map takes, with the same names:
// --encoding, --flip-green, --height, --height-scale, --wrap, --part, --fix-nonfinite, --max-size.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/cli/tool.h>

namespace glintbake::cli {

void addIngestOptions(CLI::App& app, bake::IngestOptions& options);

// Canonical JSON form of the options (for provenance metadata and --json reports).
Json ingestOptionsJson(const bake::IngestOptions& options);

// JSON form of an ingest report (counts of repaired texels, encoding, hash).
Json ingestReportJson(const bake::IngestReport& report);

// Loads a normal map for a tool: records it as an input, maps errors to cli::Error with the
// documented exit code, and warns (unless quiet) about repaired texels.
bake::NormalMap loadNormalMapForTool(Tool& tool, const std::string& path, const bake::IngestOptions& options,
                                     bake::IngestReport* report);

}  // namespace glintbake::cli
