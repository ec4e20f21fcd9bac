// SPDX-License-Identifier: Apache-2.0
// tinyexample: bakes the multi-scale tile NDFs of a small normal-map example and its placement
// (tiled or stochastic) into a tiny-example asset (formats/SPEC.md 10.8; Xing et al., "Tiny
// example-based procedural microstructures").
#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/tiny/tiny_example.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>
#include <glintbake/runtime/tiny_example_ndf.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace {

using glintbake::cli::Error;
using glintbake::cli::Json;
namespace bake = glintbake::bake;
namespace cli = glintbake::cli;
namespace format = glintbake::format;

// "A,B" as two finite numbers.
void parsePair(const std::string& text, const char* option, double out[2]) {
  try {
    size_t comma = text.find(',');
    if (comma == std::string::npos) throw std::invalid_argument("pair");
    size_t used = 0;
    const std::string a = text.substr(0, comma), b = text.substr(comma + 1);
    out[0] = std::stod(a, &used);
    if (used != a.size()) throw std::invalid_argument("pair");
    out[1] = std::stod(b, &used);
    if (used != b.size()) throw std::invalid_argument("pair");
    if (!std::isfinite(out[0]) || !std::isfinite(out[1])) throw std::invalid_argument("pair");
  } catch (const std::exception&) {
    throw Error(cli::kExitBadArguments, std::string(option) + " must be two finite numbers A,B");
  }
}

uint64_t parseBytes(const std::string& text) {
  try {
    size_t used = 0;
    const double value = std::stod(text, &used);
    const std::string suffix = text.substr(used);
    double scale = 1.0;
    static const std::string kSuffixes = "KMGT";
    if (suffix.size() == 1 && kSuffixes.find(char(std::toupper((unsigned char)suffix[0]))) != std::string::npos) {
      for (size_t k = 0; k <= kSuffixes.find(char(std::toupper((unsigned char)suffix[0]))); ++k) scale *= 1024.0;
    } else if (!suffix.empty()) {
      throw std::invalid_argument("suffix");
    }
    if (!(value > 0) || value * scale >= 1.8e19) throw std::invalid_argument("range");
    return uint64_t(value * scale);
  } catch (const std::exception&) {
    throw Error(cli::kExitBadArguments,
                "--max-memory must be a positive number of bytes, optionally with K, M, G or T");
  }
}

// The square crop (x, y, size) of a map; the whole map when size is 0.
bake::NormalMap crop(const bake::NormalMap& map, const std::vector<int>& c) {
  if (c.empty()) return map;
  if (c.size() != 3 || c[0] < 0 || c[1] < 0 || c[2] < 1 || c[0] + c[2] > map.width || c[1] + c[2] > map.height)
    throw Error(cli::kExitBadArguments, "--crop X,Y,SIZE must lie inside the " + std::to_string(map.width) + " x " +
                                            std::to_string(map.height) + " map");
  bake::NormalMap out;
  out.width = out.height = c[2];
  out.wrap = map.wrap;
  out.normals.resize(size_t(c[2]) * size_t(c[2]) * 3);
  for (int y = 0; y < c[2]; ++y)
    for (int x = 0; x < c[2]; ++x) std::memcpy(out.at(x, y), map.at(c[0] + x, c[1] + y), 12);
  return out;
}

// The layout image of --layout: every channel read (1..3), every value finite and in [0, 1].
bake::ImageChannels loadLayout(cli::Tool& t, const std::string& path) {
  bake::ImageChannels image =
      cli::unwrap(bake::loadImageChannels(path, int(format::kMaxTinyLayoutSide), int(format::kMaxTinyLayoutChannels)),
                  "--layout: ");
  t.addInput(path);
  const format::TinyLayout layout{uint32_t(image.width), uint32_t(image.height), uint32_t(image.channels),
                                  image.values.data()};
  uint64_t bad = 0;
  if (const char* why = format::checkTinyLayout(layout, &bad)) {
    const uint64_t pixel = bad / uint64_t(image.channels), channel = bad % uint64_t(image.channels);
    throw Error(cli::kExitInvalidInput,
                "--layout: " + path + ": " + why + " (pixel " + std::to_string(pixel % uint64_t(image.width)) + "," +
                    std::to_string(pixel / uint64_t(image.width)) + ", channel " + std::to_string(channel) + ")");
  }
  return image;
}

Json recordJson(const format::TinyExampleRecord& r, const format::TinyLayout* layout) {
  Json j;
  j["type"] = format::tinyExampleTypeString(format::TinyExampleType(r.type));
  j["example_size"] = r.example_size;
  j["levels"] = r.levels;
  j["ndf_res"] = r.ndf_res;
  j["sigma_r"] = r.sigma_r;
  j["matrix"] = {r.matrix[0], r.matrix[1], r.matrix[2], r.matrix[3]};
  if (r.type == uint32_t(format::TinyExampleType::kTiled)) {
    j["translate"] = {r.translate[0], r.translate[1]};
  } else {
    j["seed"] = r.seed;
    j["density"] = r.density;
    j["cell_size"] = r.cell_size;
    j["occupancy"] = r.occupancy;
    j["covered_fraction"] = format::tinyCoveredFraction(r, layout);
    j["rotate_range"] = {r.rotate_range[0], r.rotate_range[1]};
    j["scale_range"] = {r.scale_range[0], r.scale_range[1]};
    j["shear"] = {r.shear[0], r.shear[1]};
    // Only when set: assets of version 1 keep their metadata.
    if ((r.flags & format::kTinyFlagLayout) != 0) j["layout"] = true;
    if ((r.flags & format::kTinyFlagOverlap) != 0) j["overlap"] = true;
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Tool tool("tinyexample", "Bakes a tiny example's multi-scale NDF maps and placement (tiny-example asset)");
  tool.addExample("tinyexample brushed.exr --crop 64,64,32 --type tiled --rotate 90 -o tiled.gbk",
                  "A 32 x 32 crop tiled over the plane, rotated by 90 degrees.");
  tool.addExample("tinyexample flake.png --type stochastic --rotate-range 0,360 --density 0.3 --seed 5 -o sparse.gbk",
                  "Randomly rotated copies of the example covering 30% of the plane.");
  tool.addExample("tinyexample flake.png --type stochastic --rotate-range 0,180 --layout layout.png -o painted.gbk",
                  "Presence (red) and rotation (green) of the example in each layout cell painted in an image.");
  std::string input, output, type = "tiled", rotate_range, scale_range, shear, translate, layout, max_memory = "1G",
                             precision = "float16";
  double rotate = 0.0, density = 1.0, sigma_r = 0.005;
  bool rotate_given = false, mirror = false, overlap = false;
  int ndf_res = 128, zstd_level = 3;
  uint64_t seed = 0;
  std::vector<int> crop_box;
  bake::IngestOptions ingest;
  CLI::App& app = tool.app();
  app.add_option("example", input, "The example: a square normal map (or height field), 4..256 texels, a power of two")
      ->required();
  app.add_option("-o,--output", output, "Output tiny-example container (.gbk)")->required();
  app.add_option("--type", type, "Placement: tiled (one transform for all) or stochastic (one per example)")
      ->capture_default_str();
  app.add_option("--ndf-res", ndf_res, "Bins per side of every tile NDF (2..1024)")->capture_default_str();
  app.add_option("--sigma-r", sigma_r, "Intrinsic roughness of the texels' lobes (0, 1]")->capture_default_str();
  app.add_option("--seed", seed, "Stochastic: seed of the layout")->capture_default_str();
  auto* density_opt =
      app.add_option("--density", density, "Stochastic: covered fraction of the plane (0, 1]")->capture_default_str();
  auto* rot = app.add_option("--rotate", rotate, "Rotation of every example, degrees counter-clockwise");
  app.add_option("--rotate-range", rotate_range, "Stochastic: rotations drawn uniformly from A,B degrees")
      ->excludes(rot);
  app.add_option("--scale-range", scale_range, "Scales drawn uniformly from A,B (tiled: A = B), 0.125..8");
  app.add_option("--shear", shear, "Shear HX,HY of every example (|.| <= 2)");
  app.add_flag("--mirror", mirror, "Mirror every example left to right");
  app.add_flag("--overlap", overlap,
               "Stochastic: let examples overlap (cells smaller than the examples, centres anywhere in their "
               "cell); each point belongs to the example with the nearest centre among those covering it, and "
               "densities up to what full overlap covers are reachable");
  app.add_option("--translate", translate, "Tiled: position X,Y (texels) of the example's corner");
  app.add_option("--layout", layout,
                 "Stochastic: an image of 1..1024 x 1..1024 layout cells, repeating over the plane, values in "
                 "[0, 1] (integer files: value / max): channel 0 the probability that the cell holds an example, "
                 "1 (optional) its rotation within --rotate-range, 2 (optional) its scale within --scale-range; "
                 "missing channels come from --seed. With --density the presences are scaled to that covered "
                 "fraction; without, they are used as they are. More than 3 channels, NaNs or values outside "
                 "[0, 1] are refused (exit 3)");
  app.add_option("--crop", crop_box, "Use the SIZE x SIZE texels at X,Y of the map as the example")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--precision", precision,
                 "Storage of the tile images: float16 (binary16, half the bytes; float32 is used, with a warning, "
                 "when a value exceeds 65504) or float32")
      ->capture_default_str();
  app.add_option("--zstd-level", zstd_level, "zstd compression level of the sections (1..19)")->capture_default_str();
  app.add_option("--max-memory", max_memory,
                 "Refuse the bake when its tile images would need more than this many bytes (suffix K, M, G, T)")
      ->capture_default_str();
  cli::addIngestOptions(app, ingest);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    const auto t0 = std::chrono::steady_clock::now();
    rotate_given = rot->count() > 0;
    if (zstd_level < 1 || zstd_level > 19) throw Error(cli::kExitBadArguments, "--zstd-level must be in [1, 19]");
    if (precision != "float16" && precision != "float32")
      throw Error(cli::kExitBadArguments, "--precision must be float16 or float32, not \"" + precision + "\"");
    bake::tiny::TinyPlacementOptions place;
    if (type == "tiled") {
      place.type = format::TinyExampleType::kTiled;
    } else if (type == "stochastic") {
      place.type = format::TinyExampleType::kStochastic;
    } else {
      throw Error(cli::kExitBadArguments, "--type must be tiled or stochastic, not \"" + type + "\"");
    }
    const bool tiled = place.type == format::TinyExampleType::kTiled;
    if (rotate_given) place.rotate_range[0] = place.rotate_range[1] = rotate;
    if (!rotate_range.empty()) {
      if (tiled) throw Error(cli::kExitBadArguments, "--rotate-range needs --type stochastic (tiled: --rotate)");
      parsePair(rotate_range, "--rotate-range", place.rotate_range);
    }
    if (!scale_range.empty()) parsePair(scale_range, "--scale-range", place.scale_range);
    if (!shear.empty()) parsePair(shear, "--shear", place.shear);
    if (!translate.empty()) {
      if (!tiled) throw Error(cli::kExitBadArguments, "--translate needs --type tiled");
      parsePair(translate, "--translate", place.translate);
    }
    place.mirror = mirror;
    place.seed = seed;
    place.density = density;
    place.density_given = density_opt->count() > 0;
    if (tiled && density != 1.0) throw Error(cli::kExitBadArguments, "--density needs --type stochastic");
    if (tiled && !layout.empty()) throw Error(cli::kExitBadArguments, "--layout needs --type stochastic");
    if (tiled && overlap) throw Error(cli::kExitBadArguments, "--overlap needs --type stochastic");
    place.overlap = overlap;
    const uint64_t budget = parseBytes(max_memory);
    bake::ImageChannels layout_image;
    if (!layout.empty()) {
      layout_image = loadLayout(t, layout);
      place.layout = {uint32_t(layout_image.width), uint32_t(layout_image.height), uint32_t(layout_image.channels),
                      layout_image.values.data()};
    }

    bake::IngestReport ingest_report;
    const bake::NormalMap map = cli::loadNormalMapForTool(t, input, ingest, &ingest_report);
    const bake::NormalMap example = crop(map, crop_box);
    cli::check(bake::tiny::checkTinyExample(example), input + ": ");
    const int n = example.width;
    format::TinyExampleRecord record = cli::unwrap(bake::tiny::makeTinyRecord(n, ndf_res, sigma_r, place));

    // Tile images in memory: (n^2 - 1) / 3 tiles of R^2 floats, plus the section being written.
    uint64_t tiles = 0;
    for (uint32_t l = 0; l < record.levels; ++l) {
      const uint64_t m = format::tinyTilesPerSide(record.example_size, l);
      tiles += m * m;
    }
    const uint64_t image_bytes = uint64_t(ndf_res) * uint64_t(ndf_res) * 4;
    const uint64_t raw_bytes = tiles * image_bytes;
    const uint64_t estimate = raw_bytes + (uint64_t(n) * n / 4) * image_bytes + (uint64_t(n) * n * 32);
    if (estimate > budget)
      throw Error(cli::kExitRuntime, "the tile images need about " + std::to_string((estimate + (1u << 20) - 1) >> 20) +
                                         " MiB (" + std::to_string(tiles) + " tiles of " + std::to_string(ndf_res) +
                                         "^2 bins), more than --max-memory " + max_memory);

    const auto t1 = std::chrono::steady_clock::now();
    const std::vector<float> texels = bake::tiny::tinyTexels(example);
    const std::vector<std::vector<float>> levels = bake::tiny::bakeTinyLevels(texels, n, sigma_r, ndf_res);
    const double tile_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    if (precision == "float16") {
      if (bake::tiny::tinyLevelsFitHalf(levels)) {
        record = bake::tiny::withHalfLevels(record);
      } else {
        t.warning("a tile density exceeds 65504 (the largest float16): the tile images are stored as float32");
      }
    }

    cli::ContainerOutput out(t, output, format::AssetKind::kTinyExample, zstd_level);
    cli::check(bake::tiny::writeTinyExampleSections(out.writer(), record, texels, levels,
                                                    place.layout.width > 0 ? &place.layout : nullptr));
    Json params;
    params["type"] = type;
    params["ndf_res"] = ndf_res;
    params["sigma_r"] = sigma_r;
    params["rotate_range"] = {place.rotate_range[0], place.rotate_range[1]};
    params["scale_range"] = {place.scale_range[0], place.scale_range[1]};
    params["shear"] = {place.shear[0], place.shear[1]};
    params["mirror"] = mirror;
    if (tiled) params["translate"] = {place.translate[0], place.translate[1]};
    if (!tiled) {
      params["seed"] = seed;
      params["density"] = density;
      if (overlap) params["overlap"] = true;
      if (!layout.empty()) {
        params["layout"] = cli::baseName(layout);
        params["layout_size"] = {layout_image.width, layout_image.height, layout_image.channels};
        params["density_given"] = place.density_given;
      }
    }
    if (!crop_box.empty()) params["crop"] = crop_box;
    params["precision"] = precision;
    params["zstd_level"] = zstd_level;
    params["ingest"] = cli::ingestOptionsJson(ingest);
    Json meta = out.makeMetadata(params);
    meta["asset"] = recordJson(record, place.layout.width > 0 ? &place.layout : nullptr);
    out.finish(meta);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    if (t.common().json) {
      Json doc;
      doc["tool"] = "tinyexample";
      doc["input"] = cli::baseName(input);
      doc["output"] = cli::baseName(output);
      doc["asset"] = recordJson(record, place.layout.width > 0 ? &place.layout : nullptr);
      doc["levels"] = Json::array();
      for (uint32_t l = 0; l < record.levels; ++l) {
        const uint32_t m = format::tinyTilesPerSide(record.example_size, l);
        doc["levels"].push_back({{"level", l},
                                 {"tiles_per_side", m},
                                 {"tile_texels", 2u << l},
                                 {"raw_bytes", uint64_t(m) * m * image_bytes}});
      }
      doc["tiles"] = tiles;
      doc["raw_bytes"] = raw_bytes;
      doc["file_bytes"] = out.bytesWritten();
      doc["flakes"] = true;  // every placement answers small footprints from the plane's flakes
      doc["precision"] = (record.flags & format::kTinyFlagHalf) != 0 ? "float16" : "float32";
      doc["tile_seconds"] = tile_seconds;
      doc["seconds"] = seconds;
      t.printJson(doc);
    } else {
      t.info("wrote " + output + ": " + std::to_string(n) + "^2 example, " + std::to_string(record.levels) +
             " levels, " + std::to_string(tiles) + " tiles, " + std::to_string(out.bytesWritten()) + " bytes (" +
             std::to_string(raw_bytes) + " raw) in " + std::to_string(seconds) + " s");
    }
    return cli::kExitOk;
  });
}
