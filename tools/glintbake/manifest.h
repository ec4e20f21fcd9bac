// SPDX-License-Identifier: Apache-2.0
// glintbake bake: the manifest (schemas/glintbake-manifest.schema.json), the steps that bake it
// and the incremental state. Every asset is baked by running its tool (located beside the
// glintbake binary) as a subprocess: the tools' command lines are the contract, here as on a farm.
#pragma once

#include <glintbake/cli/tool.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace glintbake::batch {

// One asset of the manifest, resolved: paths relative to the manifest's folder, defaults applied.
struct Asset {
  std::string name;                     // unique within the manifest
  std::string tool;                     // ndfgen, tensorpack, mapgen, ltcfit, ...
  std::vector<std::string> args;        // positional arguments before the inputs (mapgen's kind, ...)
  std::vector<std::string> inputs;      // input files
  std::string output;                   // the asset written
  std::vector<std::string> options;     // the tool's options, as command-line words
  int shards = 1;                       // > 1: --shard I/N on that many tasks, then glintinfo merge
  std::string key;                      // incremental key: tool version, options, input content hashes
  std::vector<std::string> input_hashes;
};

struct Manifest {
  std::string path;  // as given
  std::string dir;   // its folder ("." when none)
  std::string state_path;
  std::vector<Asset> assets;
};

// Reads and checks the manifest; throws cli::Error (exit 2 unreadable, 3 malformed, naming the
// asset and field).
Manifest readManifest(const std::string& path);

// Locates a tool beside the glintbake binary (argv0's folder, then /proc/self/exe's); throws
// cli::Error exit 2 when it is missing.
std::string toolPath(const std::string& tool);

// Fills each asset's input hashes and key (runs each tool's --version once). Throws exit 2 on
// unreadable inputs.
void computeKeys(Manifest& manifest);

// One command of a bake: an asset's whole bake, one of its shards, or its merge.
struct Step {
  size_t asset = 0;
  int shard = -1;  // -1: the whole asset (or the merge, when merge is set)
  bool merge = false;
  std::vector<std::string> argv;  // argv[0]: the program
};

// The folder of an asset's shard parts while it is baked ("<output>.shards").
std::string partsDir(const Asset& asset);
std::string partPath(const Asset& asset, int shard);

// The steps of an asset: one bake, or its shards then the merge (last). threads: -j of each tool.
std::vector<Step> stepsOf(const Manifest& manifest, size_t asset, int threads);

// Incremental state: asset name -> {key, output hash}.
struct StateEntry {
  std::string key, output_hash;
};
std::map<std::string, StateEntry> readState(const std::string& path);
void writeState(const std::string& path, const std::map<std::string, StateEntry>& state);

// True when the asset's output exists, its content hash and key equal the recorded ones.
bool upToDate(const Asset& asset, const std::map<std::string, StateEntry>& state);

// A command line as one shell-quoted string.
std::string shellQuote(const std::vector<std::string>& argv);

}  // namespace glintbake::batch
