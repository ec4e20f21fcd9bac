// SPDX-License-Identifier: Apache-2.0
// glintquery materialise: the normal map of a rectangle of cells of a wang-tiles asset's implicit
// grid, as the runtime lays the tiles (WangGridTexels), so that the reference evaluator and the
// renderer can be run on the very surface the asset answers for.
#include "commands.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/runtime/wang_ndf.h>

#include <cmath>
#include <string>
#include <vector>

namespace glintbake::glintquery {

namespace rt = glintbake::runtime;
using cli::Error;

namespace {

// Bounds of the materialised map: a side of at most 16384 texels and 2^25 texels in all (400 MB of
// float RGB), refused before anything is allocated.
constexpr int64_t kMaxMaterialisedSide = 16384;
constexpr int64_t kMaxMaterialisedTexels = int64_t(1) << 25;

// "I0,J0,NX,NY": integers, NX and NY >= 1.
void parseCells(const std::string& text, int64_t cells[4]) {
  size_t at = 0;
  for (int k = 0; k < 4; ++k) {
    const size_t end = k < 3 ? text.find(',', at) : text.size();
    bool ok = end != std::string::npos && end > at;
    if (ok) {
      const std::string part = text.substr(at, end - at);
      try {
        size_t used = 0;
        cells[k] = std::stoll(part, &used);
        ok = used == part.size();
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok || (k >= 2 && cells[k] < 1) || (k < 2 && std::llabs(cells[k]) > (int64_t(1) << 40)))
      throw Error(
          cli::kExitBadArguments,
          "--cells expects four integers I0,J0,NX,NY with NX, NY >= 1 and |I0|, |J0| <= 2^40 (got '" + text + "')");
    at = end + 1;
  }
}

}  // namespace

CLI::App* addMaterialiseCommand(CLI::App& app, MaterialiseOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "materialise", "The normal map of a rectangle of a wang-tiles asset's implicit grid (cells I0..I0+NX-1, ...)");
  cmd->add_option("asset", options.asset, "wang-tiles asset (.gbk)")->required();
  cmd->add_option("--cells", options.cells, "Grid cells I0,J0,NX,NY (cell (i, j) covers texels [iT, iT + T) x ...)")
      ->required();
  cmd->add_option("-o,--output", options.output, "Output normal map (.exr: signed float n_x, n_y, n_z)")->required();
  return cmd;
}

int runMaterialise(cli::Tool& tool, const MaterialiseOptions& options) {
  int64_t cells[4];
  parseCells(options.cells, cells);
  if (!bake::isFloatImagePath(options.output) || bake::imageExtension(options.output) != "exr")
    throw Error(cli::kExitBadArguments, "-o " + options.output + ": the normal map must be written as .exr");
  tool.addInput(options.asset);
  format::Reader reader;
  const format::ContainerStatus cs = reader.open(options.asset);
  if (cs != format::ContainerStatus::kOk)
    throw Error(cli::exitCodeOf(cs), "cannot open " + options.asset + ": " + format::statusString(cs));
  rt::WangNdf wang;
  const rt::RuntimeStatus st = wang.load(reader);
  if (st != rt::RuntimeStatus::kOk)
    throw Error(cli::exitCodeOf(st),
                "cannot open " + options.asset + " as a wang-tiles asset: " + rt::statusString(st));
  const int64_t t = wang.record().tile_size;
  const int64_t w = cells[2] * t, h = cells[3] * t;
  if (cells[2] > kMaxMaterialisedSide || cells[3] > kMaxMaterialisedSide || w > kMaxMaterialisedSide ||
      h > kMaxMaterialisedSide || w * h > kMaxMaterialisedTexels)
    throw Error(cli::kExitBadArguments, "--cells " + options.cells + " gives a " + std::to_string(w) + " x " +
                                            std::to_string(h) +
                                            " texel map: at most 16384 per side and 2^25 texels in all");
  const rt::WangGridTexels texels(wang, cells[0], cells[1], int(cells[2]), int(cells[3]));
  std::vector<float> rgb(size_t(w) * size_t(h) * 3);
  for (int64_t y = 0; y < h; ++y) {
    for (int64_t x = 0; x < w; ++x) {
      float n[2];
      texels.normal(int(x), int(y), n);
      float* p = rgb.data() + (size_t(y) * size_t(w) + size_t(x)) * 3;
      p[0] = n[0];
      p[1] = n[1];
      p[2] = float(std::sqrt(std::max(0.0, 1.0 - double(n[0]) * n[0] - double(n[1]) * n[1])));
    }
  }
  cli::check(bake::writeImage(options.output, int(w), int(h), 3, rgb.data()));
  tool.addOutput(options.output);
  if (tool.common().json) {
    cli::Json doc;
    doc["tool"] = "glintquery";
    doc["op"] = "materialise";
    doc["asset"] = cli::baseName(options.asset);
    doc["output"] = cli::baseName(options.output);
    doc["cells"] = {cells[0], cells[1], cells[2], cells[3]};
    doc["tile_size"] = t;
    doc["size"] = {w, h};
    tool.printJson(doc);
  } else {
    tool.info("wrote " + options.output + " (" + std::to_string(w) + "x" + std::to_string(h) + ")");
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintquery
