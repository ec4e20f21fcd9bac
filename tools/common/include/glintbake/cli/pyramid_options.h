// SPDX-License-Identifier: Apache-2.0
// The NDF pyramid options every tool that bakes a pyramid from a normal map takes, with the same
// names and defaults (ndfgen, tensorpack): --ndf-res, --sigma-r, --stride, --sigma0, --levels,
// --converge-mse, --rate, --region; plus the per-level progress bar of a pyramid build.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>

#include <memory>
#include <string>
#include <vector>

namespace glintbake::cli {

struct PyramidCliOptions {
  bake::ndf::PyramidOptions options;
  std::string levels_text = "auto";  // "auto" or a positive integer; resolvePyramidOptions fills options.levels
  bool flakes = true;                // write the flakes section (formats/SPEC.md 10.5); --no-flakes
  int lobes = bake::ndf::kDefaultLobesPerTile;  // lobes per tile of the clustered path; --lobes
  std::vector<CLI::Option*> flags;              // the registered options (to reject them where they do not apply)
  std::string max_memory_text;  // --max-memory: bytes, with an optional K, M, G or T suffix (powers of 1024)
};

// Registers the options; region_help describes --region for this tool.
void addPyramidOptions(CLI::App& app, PyramidCliOptions& pyramid, const std::string& region_help);

// Parses --levels and validates every option (Error with exit 1 naming the option).
void resolvePyramidOptions(PyramidCliOptions& pyramid);

// The estimated peak memory, in bytes, of baking `map` with these options on `threads` threads
// (pyramid_builder.h and tensor_pack.h list the terms): the map, its flakes (24 bytes each), two
// chunks, per-thread scratch, and for tensorpack (tensor = true) the group tensors in flight.
uint64_t estimateBakeBytes(const PyramidCliOptions& pyramid, const bake::NormalMap& map, int threads, bool tensor);

// Refuses the bake up front (Error exit 4 naming both figures) when --max-memory is given and the
// estimate exceeds it; exit 1 when the value does not parse.
void checkMemoryBudget(const PyramidCliOptions& pyramid, const bake::NormalMap& map, int threads, bool tensor);

// Canonical JSON form of the options (for provenance metadata and --json reports).
Json pyramidOptionsJson(const PyramidCliOptions& pyramid);

// The hand-over of an uncompressed pyramid with these options (--sigma0, --lobes) on this map.
bake::ndf::FlakesHandover defaultFlakesHandover(const PyramidCliOptions& pyramid, const bake::NormalMap& map);

// Writes the flakes section of the map (unless --no-flakes) with this hand-over; returns its raw
// size in bytes (0 when left out). Error exit 4 on failure.
uint64_t writeFlakes(format::Writer& writer, const bake::NormalMap& map, const PyramidCliOptions& pyramid,
                     const bake::ndf::FlakesHandover& handover);

// The hand-over and size of a flakes section as the tools report them (metadata and --json).
Json flakesJson(const bake::ndf::FlakesHandover& handover, uint64_t bytes);

// Rejects maps too small to bake (exit 3, naming the file and its size).
void requireBakeableMap(const bake::NormalMap& map, const std::string& path);

// A progress bar per pyramid level, fed by the builder's progress callback.
class LevelProgress {
 public:
  explicit LevelProgress(Tool& tool) : tool_(tool) {}
  ~LevelProgress() { finish(); }
  bake::ndf::PyramidProgress callback();
  void finish();

 private:
  Tool& tool_;
  std::unique_ptr<Progress> bar_;
  int level_ = -1;
  uint64_t done_ = 0;
};

}  // namespace glintbake::cli
