// SPDX-License-Identifier: Apache-2.0
// glintquery materialise: the normal map of a rectangle of cells of an unbounded asset's plane, so
// that the reference evaluator and the renderer can be run on the very surface the asset answers
// for: a wang-tiles grid as the runtime lays the tiles (WangGridTexels), or a tiny-example plane with
// its examples placed and transformed as the runtime places them (TinyPlaneTexels; cells of the
// example's size).
#include "commands.h"

#include <glintbake/bake/io/image_io.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/runtime/tiny_example_ndf.h>
#include <glintbake/runtime/wang_ndf.h>

#include <cmath>
#include <memory>
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
      "materialise",
      "The normal map of a rectangle of a wang-tiles or tiny-example asset's plane (cells I0..I0+NX-1, ...)");
  cmd->add_option("asset", options.asset, "wang-tiles or tiny-example asset (.gbk)")->required();
  cmd->add_option("--cells", options.cells,
                  "Cells I0,J0,NX,NY: cell (i, j) covers texels [iT, iT + T) x [jT, jT + T) of the plane, T the "
                  "tile size (wang-tiles) or the example size n (tiny-example; the examples as placed and "
                  "transformed, read bilinearly, slopes mapped by the inverse transpose, uncovered texels flat)")
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
  // The cell side T and the texels of the rectangle, from the asset's kind.
  rt::WangNdf wang;
  rt::TinyExampleNdf tiny;
  std::unique_ptr<rt::TexelSource> texels;
  int64_t t = 0;
  const std::string kind = format::assetKindString(reader.kind());
  if (reader.kind() == format::AssetKind::kWangTiles) {
    const rt::RuntimeStatus st = wang.load(reader);
    if (st != rt::RuntimeStatus::kOk)
      throw Error(cli::exitCodeOf(st),
                  "cannot open " + options.asset + " as a wang-tiles asset: " + rt::statusString(st));
    t = wang.record().tile_size;
  } else if (reader.kind() == format::AssetKind::kTinyExample) {
    const rt::RuntimeStatus st = tiny.load(reader);
    if (st != rt::RuntimeStatus::kOk)
      throw Error(cli::exitCodeOf(st),
                  "cannot open " + options.asset + " as a tiny-example asset: " + rt::statusString(st));
    t = tiny.record().example_size;
  } else {
    throw Error(cli::kExitUnsupported,
                options.asset + " is a " + kind + " asset: materialise needs a wang-tiles or tiny-example asset");
  }
  const int64_t w = cells[2] * t, h = cells[3] * t;
  if (cells[2] > kMaxMaterialisedSide || cells[3] > kMaxMaterialisedSide || w > kMaxMaterialisedSide ||
      h > kMaxMaterialisedSide || w * h > kMaxMaterialisedTexels)
    throw Error(cli::kExitBadArguments, "--cells " + options.cells + " gives a " + std::to_string(w) + " x " +
                                            std::to_string(h) +
                                            " texel map: at most 16384 per side and 2^25 texels in all");
  std::unique_ptr<rt::TinyPlaneTexels> plane;
  if (reader.kind() == format::AssetKind::kWangTiles)
    texels.reset(new rt::WangGridTexels(wang, cells[0], cells[1], int(cells[2]), int(cells[3])));
  else
    plane.reset(new rt::TinyPlaneTexels(tiny, cells[0] * t, cells[1] * t, int(w), int(h)));
  std::vector<float> rgb(size_t(w) * size_t(h) * 3);
  int64_t covered = 0;
  for (int64_t y = 0; y < h; ++y) {
    for (int64_t x = 0; x < w; ++x) {
      float n[2];
      if (plane)
        covered += plane->texel(int(x), int(y), n) ? 1 : 0;
      else
        texels->normal(int(x), int(y), n);
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
    doc["kind"] = kind;
    doc["cells"] = {cells[0], cells[1], cells[2], cells[3]};
    doc["tile_size"] = t;
    doc["size"] = {w, h};
    if (plane) doc["covered_fraction"] = double(covered) / double(w * h);
    tool.printJson(doc);
  } else {
    tool.info("wrote " + options.output + " (" + std::to_string(w) + "x" + std::to_string(h) + ")");
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintquery
