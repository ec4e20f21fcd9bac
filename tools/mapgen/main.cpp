// SPDX-License-Identifier: Apache-2.0
// mapgen: writes procedural microstructure normal maps with known statistics (flat, beckmann,
// brushed, scratches, flakes), deterministic by seed; see libbake mapgen/mapgen.h for the models.
#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/tool.h>

#include <cctype>
#include <cmath>
#include <string>

namespace {

using glintbake::cli::Error;
using glintbake::cli::Json;
namespace bake = glintbake::bake;
namespace cli = glintbake::cli;

constexpr int kDefaultMaxSize = 16384;

// The parameters the kind uses, in canonical form.
Json parametersJson(bake::MapKind kind, const bake::MapParams& p) {
  Json j = Json::object();
  switch (kind) {
    case bake::MapKind::kFlat:
      break;
    case bake::MapKind::kBeckmann:
      j["alpha"] = p.alpha;
      j["cell"] = bake::effectiveCell(kind, p);
      break;
    case bake::MapKind::kBrushed:
      j["alpha_x"] = p.alpha_x;
      j["alpha_y"] = p.alpha_y;
      j["cell"] = bake::effectiveCell(kind, p);
      break;
    case bake::MapKind::kScratches:
      j["density"] = p.density;
      j["width"] = p.width;
      j["slope"] = p.scratch_slope;
      break;
    case bake::MapKind::kFlakes:
      j["cone"] = p.cone_degrees;
      j["cell"] = bake::effectiveCell(kind, p);
      break;
  }
  return j;
}

Json statisticsJson(const bake::MapStatistics& s) {
  Json j;
  j["mean_normal"] = {s.mean_normal[0], s.mean_normal[1], s.mean_normal[2]};
  j["slope_mean"] = {s.slope_mean[0], s.slope_mean[1]};
  j["slope_std"] = {s.slope_std[0], s.slope_std[1]};
  j["max_angle_degrees"] = s.max_angle_degrees;
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Tool tool("mapgen", "Writes procedural microstructure normal maps with known statistics");
  std::string kind_name, output;
  bake::MapParams params;
  int max_size = kDefaultMaxSize;
  int png_bits = 16;
  bool half = false;
  tool.addExample("mapgen brushed -o brushed.png --size 512", "A 512 x 512 brushed-metal normal map.");
  tool.addExample("mapgen flakes -o flakes.exr --cone 15 --seed 7", "A flake map with normals within 15 degrees of the surface normal.");
  CLI::App& app = tool.app();
  app.add_option("kind", kind_name, "Map kind: " + bake::mapKindList())->required();
  app.add_option("-o,--output", output, "Output image: .exr (signed float RGB), .png or .tif ((n+1)/2, 16-bit)")
      ->required();
  app.add_option("--size", params.size, "Width and height in texels (1..--max-size)")->capture_default_str();
  app.add_option("--seed", params.seed, "Random seed (equal seeds give identical files)")->capture_default_str();
  app.add_option("--alpha", params.alpha, "beckmann: roughness alpha, slopes ~ N(0, alpha^2/2) per axis (0, 4]")
      ->capture_default_str();
  app.add_option("--alpha-x", params.alpha_x, "brushed: roughness along x, the brushing direction (0, 4]")
      ->capture_default_str();
  app.add_option("--alpha-y", params.alpha_y, "brushed: roughness along y (0, 4]")->capture_default_str();
  app.add_option("--density", params.density, "scratches: scratches per 1000 texel^2 [0, 1000]")->capture_default_str();
  app.add_option("--width", params.width, "scratches: groove width in texels (0, min(256, size/4)]")
      ->capture_default_str();
  app.add_option("--slope", params.scratch_slope, "scratches: groove wall slope (0, 10]")->capture_default_str();
  app.add_option("--cone", params.cone_degrees, "flakes: half-angle of the normal cone, degrees [0, 89]")
      ->capture_default_str();
  app.add_option("--cell", params.cell,
                 "beckmann/brushed: surface kernel std in texels (default 3); flakes: mean cell size in "
                 "texels (default 8)");
  app.add_option("--max-size", max_size, "Largest accepted --size (1..1048576)")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  app.add_option("--png-bits", png_bits, "Bits per channel of integer outputs (8 or 16)")
      ->check(CLI::IsMember({8, 16}))
      ->capture_default_str();
  app.add_flag("--half", half, "Store EXR output as half floats");

  return tool.run(argc, argv, [&](cli::Tool& t) {
    bake::MapKind kind;
    if (!bake::mapKindFromString(kind_name, &kind)) {
      throw Error(cli::kExitBadArguments, "unknown kind '" + kind_name + "' (expected " + bake::mapKindList() + ")");
    }
    if (params.size < 1 || params.size > max_size) {
      throw Error(cli::kExitBadArguments, "--size must be in [1, " + std::to_string(max_size) + "], got " +
                                              std::to_string(params.size) +
                                              (params.size > max_size ? " (raise the limit with --max-size)" : ""));
    }
    if (output == "-")
      throw Error(cli::kExitBadArguments, "images cannot be written to standard output ('-'): name a .exr, .png or .tif file");
    const std::string ext = bake::imageExtension(output);
    if (ext != "exr" && ext != "png" && ext != "tif" && ext != "tiff") {
      throw Error(cli::kExitBadArguments, "output " + output + " must end in .exr, .png or .tif");
    }
    const bake::BakeStatus valid = bake::validateMapParams(kind, params);
    if (!valid) throw Error(cli::kExitBadArguments, valid.error().message);

    const bake::NormalMap map = bake::generateMap(kind, params);
    const bake::MapStatistics stats = bake::measureMap(map);

    bake::ImageWriteOptions write_options;
    write_options.png_bits = png_bits;
    write_options.half_float = half;
    cli::check(bake::writeNormalMap(output, map, write_options));
    t.addOutput(output);

    if (t.common().json) {
      Json doc;
      doc["tool"] = "mapgen";
      doc["kind"] = bake::mapKindString(kind);
      doc["output"] = output;
      doc["size"] = params.size;
      doc["seed"] = params.seed;
      doc["parameters"] = parametersJson(kind, params);
      doc["encoding"] = bake::isFloatImagePath(output) ? (half ? "half" : "float") : "unorm" + std::to_string(png_bits);
      doc["statistics"] = statisticsJson(stats);
      t.printJson(doc);
    } else {
      t.info("wrote " + output + ": slope std (" + std::to_string(stats.slope_std[0]) + ", " +
             std::to_string(stats.slope_std[1]) + "), largest tilt " + std::to_string(stats.max_angle_degrees) +
             " degrees");
    }
    return cli::kExitOk;
  });
}
