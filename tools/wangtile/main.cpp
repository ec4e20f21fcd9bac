// SPDX-License-Identifier: Apache-2.0
// wangtile: bakes an edge-coloured Wang tile set from an example normal map (Cohen et al. 2003)
// into a wang-tiles asset (formats/SPEC.md 10.7): the tiles' texels, their edge colours and the
// edge-code-to-tile map, and every tile's NDF pyramid over the tile extended by a margin,
// compressed as tensorpack compresses a map's (libbake/wang/wang.h). The runtime lays the tiles
// on an implicit hashed grid covering the unbounded plane (runtime/wang_ndf.h).
#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/wang/wang.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/ingest_options.h>
#include <glintbake/cli/pyramid_options.h>
#include <glintbake/cli/shard_output.h>
#include <glintbake/cli/tensor_options.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/kinds/wang.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using glintbake::cli::Error;
using glintbake::cli::Json;
namespace bake = glintbake::bake;
namespace cli = glintbake::cli;
namespace format = glintbake::format;
namespace wang = glintbake::bake::wang;

// The side of the square a footprint of the largest sigma is answered over: the tile's NDF asset
// extends one tile beyond it on every side (footprints within the cover radius, at most T).
int marginFor(int tile_size) { return tile_size; }

struct Options {
  std::string input, output, atlas;
  wang::WangTileOptions tiles;
  uint64_t grid_seed = 1;
  bool plain_cut = false, uncompressed = false;
  bake::IngestOptions ingest;
  cli::PyramidCliOptions pyramid;
  // Every tile carries its own pyramid, so the exact-level budget stays at 4 MiB a tile (tensorpack's
  // 16 MiB would store 12 x 12-centre levels exactly for each of the C^4 tiles).
  cli::TensorCliOptions tensor = [] {
    cli::TensorCliOptions t;
    t.exact_mib = 4.0;
    return t;
  }();
  cli::ShardCliOptions shard;
};

void addOptions(CLI::App& app, Options& o) {
  app.add_option("input", o.input, "Example normal map (or height field with --height)")->required();
  app.add_option("-o,--output", o.output, "Output wang-tiles container")->required();
  app.add_option("--colors", o.tiles.colors, "Colours per edge C (2..4): a complete set of C^4 tiles")
      ->capture_default_str();
  app.add_option("--tile-size", o.tiles.tile_size, "Texels per tile side T (8..4096, at most the example's size)")
      ->capture_default_str();
  app.add_option("--seed", o.tiles.seed, "Selects the edge samples of the example")->capture_default_str();
  app.add_option("--grid-seed", o.grid_seed, "Selects the implicit grid's tile layout (stored; the runtime hashes it)")
      ->capture_default_str();
  app.add_flag("--plain-cut", o.plain_cut, "Straight diagonal cuts instead of minimum-error ones");
  app.add_option("--atlas", o.atlas, "Also write the tiles side by side as an image (.exr signed, .png encoded)");
  app.add_flag("--uncompressed", o.uncompressed, "Store each tile's NDF pyramid uncompressed (ndf-pyramid)");
  cli::addTensorPackOptions(app, o.tensor, "--cp-seed");
  cli::addPyramidOptions(app, o.pyramid, "Footprint centres per group side (1..256)");
  cli::addIngestOptions(app, o.ingest);
  cli::addShardOption(app, o.shard);
}

// The pyramid and hand-over of every tile: levels up to the largest footprint (unless --levels),
// flakes below the first level's sigma within what one tile's window allows.
struct Plan {
  int margin = 0;
  double max_sigma = 0.0, flakes_up_to = 0.0, pyramid_from = 0.0;
};

Plan planTiles(Options& o) {
  Plan p;
  const int T = o.tiles.tile_size;
  p.margin = marginFor(T);
  p.max_sigma = format::wangMaxSigma(uint32_t(T));
  bake::ndf::PyramidOptions& po = o.pyramid.options;
  if (po.sigma0 > p.max_sigma) {
    throw Error(cli::kExitBadArguments, "--sigma0 must be at most the largest footprint of the tile size, " +
                                            std::to_string(p.max_sigma) + " texels at --tile-size " +
                                            std::to_string(T));
  }
  if (po.levels == 0) {
    int levels = 1;
    while (po.sigma0 * std::ldexp(1.0, levels - 1) < p.max_sigma && levels < bake::ndf::kMaxPyramidLevels) ++levels;
    po.levels = levels;
  }
  if (o.pyramid.flakes) {
    const bake::ndf::FlakesHandover h = bake::ndf::defaultHandover(po.sigma0, 0);
    // The exact path's window (1.5 cover radii) must stay within one tile.
    double window_sigma = p.max_sigma;
    while (1.5 * format::wangCoverRadius(window_sigma) > double(T)) window_sigma *= 0.99;
    p.pyramid_from = std::min({h.pyramid_from, p.max_sigma, window_sigma});
    p.flakes_up_to = std::min(h.flakes_up_to, p.pyramid_from / std::sqrt(2.0));
  }
  return p;
}

Json seamJson(const wang::SeamError& e) {
  return {{"mean_degrees", e.mean_degrees}, {"max_degrees", e.max_degrees}, {"texels", e.texels}};
}

struct TileTotals {
  uint64_t ndf_bytes = 0, raw_bytes = 0, groups = 0;
  double error_squared = 0.0, norm_squared = 0.0, max_tile_error = 0.0;
  int levels = 0;
  std::vector<double> level_sigmas;
};

void addTile(TileTotals& s, const wang::WangTileNdfReport& r, size_t bytes, bool uncompressed) {
  s.ndf_bytes += bytes;
  if (uncompressed) {
    s.levels = int(r.pyramid.levels.size());
    s.level_sigmas.clear();
    for (const auto& l : r.pyramid.levels) s.level_sigmas.push_back(l.geometry.sigma), s.raw_bytes += l.raw_bytes;
    return;
  }
  s.raw_bytes += r.pack.raw_bytes;
  s.groups += r.pack.groups;
  s.levels = int(r.pack.levels.size());
  s.level_sigmas.clear();
  for (const auto& l : r.pack.levels) {
    s.level_sigmas.push_back(l.sigma);
    s.error_squared += l.error_squared;
    s.norm_squared += l.norm_squared;
  }
  s.max_tile_error = std::max(s.max_tile_error, r.pack.relative_error);
}

}  // namespace

int main(int argc, char** argv) {
  cli::Tool tool("wangtile",
                 "Bakes a Wang tile set from an example normal map into a wang-tiles asset for unbounded surfaces");
  tool.addExample("wangtile scratches.png -o floor.gbk --atlas floor_tiles.exr",
                  "A 16-tile set (two colours per edge) and an image of its tiles side by side.");
  tool.addExample("wangtile scratches.png -o floor.gbk --tile-size 128 --colors 3 --json",
                  "81 smaller tiles; the summary (seams, sizes, times) as JSON.");
  Options o;
  addOptions(tool.app(), o);
  return tool.run(argc, argv, [&](cli::Tool& t) {
    const auto t0 = std::chrono::steady_clock::now();
    cli::resolveTensorPackOptions(t.app(), o.tensor);
    cli::resolvePyramidOptions(o.pyramid);
    o.tiles.optimise = !o.plain_cut;
    if (o.tiles.colors < int(format::kMinWangColors) || o.tiles.colors > int(format::kMaxWangColors))
      throw Error(cli::kExitBadArguments, "--colors must be in [2, 4]");
    if (o.tiles.tile_size < int(format::kMinWangTileSize) || o.tiles.tile_size > int(format::kMaxWangTileSize))
      throw Error(cli::kExitBadArguments, "--tile-size must be in [8, 4096]");
    const int res = o.pyramid.options.splat.ndf_res;
    if (!o.uncompressed && res % o.tensor.pack.block != 0)
      throw Error(cli::kExitBadArguments,
                  "--block " + std::to_string(o.tensor.pack.block) + " must divide --ndf-res " + std::to_string(res));
    if (!o.atlas.empty() && bake::imageExtension(o.atlas).empty())
      throw Error(cli::kExitBadArguments, "--atlas needs an image extension (.exr, .png, ...)");
    cli::resolveShardOption(o.shard);
    if (o.shard.active() && !o.atlas.empty())
      throw Error(cli::kExitBadArguments, "--atlas is written by the bake without --shard");
    Plan plan = planTiles(o);

    bake::IngestReport ingest_report;
    const bake::NormalMap example = cli::loadNormalMapForTool(t, o.input, o.ingest, &ingest_report);
    cli::requireBakeableMap(example, o.input);
    // Memory: the tiles, plus one tile's pyramid build at a time over the extended square.
    {
      bake::NormalMap extended;
      extended.width = extended.height = o.tiles.tile_size + 2 * plan.margin;
      cli::checkMemoryBudget(o.pyramid, extended, t.threadCount(), !o.uncompressed);
    }
    const auto t_tiles = std::chrono::steady_clock::now();
    bake::Result<wang::WangTileSet> built = wang::buildWangTiles(example, o.tiles);
    if (!built) throw Error(cli::exitCodeOf(built.error()), o.input + ": " + built.error().message);
    const wang::WangTileSet& set = built.value();
    const double tile_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_tiles).count();

    Json params;
    params["colors"] = o.tiles.colors;
    params["tile_size"] = o.tiles.tile_size;
    params["seed"] = o.tiles.seed;
    params["grid_seed"] = o.grid_seed;
    params["plain_cut"] = o.plain_cut;
    params["uncompressed"] = o.uncompressed;
    params["margin"] = plan.margin;
    Json pj = cli::pyramidOptionsJson(o.pyramid);
    pj["ingest"] = cli::ingestOptionsJson(o.ingest);
    params["pyramid"] = pj;
    if (!o.uncompressed) params["tensor"] = cli::tensorPackOptionsJson(o.tensor);

    // Every tile's NDF asset, one after another (each bake runs in parallel inside).
    wang::WangNdfOptions nopt;
    nopt.pyramid = o.pyramid.options;
    nopt.pack = o.tensor.pack;
    nopt.uncompressed = o.uncompressed;
    nopt.margin = plan.margin;
    nopt.zstd_level = o.tensor.zstd_level;
    const format::AssetKind tile_kind = o.uncompressed ? format::AssetKind::kNdfPyramid : format::AssetKind::kTensorNdf;
    Json tile_meta = t.makeMetadata(tile_kind, params);
    tile_meta["asset"] = {{"wang_tile_margin", plan.margin}};
    const std::string tile_meta_text = tile_meta.dump();
    // The container: record, edges, texels, then the tiles' assets in tile order; its metadata
    // depends on the options and the tile set only, so every shard of a sharded bake knows it.
    const format::WangRecord rec =
        wang::wangRecord(set, nopt, o.grid_seed, plan.flakes_up_to, plan.pyramid_from, plan.max_sigma);
    Json asset;
    asset["tile_count"] = set.tile_count;
    asset["tile_size"] = set.tile_size;
    asset["colors"] = set.colors;
    asset["ndf_res"] = res;
    asset["max_sigma"] = plan.max_sigma;
    asset["flakes_up_to"] = plan.flakes_up_to;
    asset["pyramid_from"] = plan.pyramid_from;
    asset["levels"] = o.pyramid.options.levels;  // every tile's pyramid has exactly these
    asset["seam"] = seamJson(set.seam);
    asset["plain_seam"] = seamJson(set.plain_seam);
    Json meta = t.makeMetadata(format::AssetKind::kWangTiles, params);
    meta["asset"] = asset;

    // One unit per tile (equal cost), dealt out as libbake/shard/shard.h does.
    std::vector<int> owners(size_t(set.tile_count), 0);
    if (o.shard.active())
      owners = bake::shard::assignShards(std::vector<double>(size_t(set.tile_count), 1.0), o.shard.spec.count);
    const int me = o.shard.active() ? o.shard.spec.index : 0;
    std::vector<std::vector<uint8_t>> tile_bytes(size_t(set.tile_count));
    TileTotals totals;
    uint64_t units = 0;
    const auto t_ndf = std::chrono::steady_clock::now();
    {
      std::unique_ptr<cli::Progress> bar = t.progress("tiles", uint64_t(set.tile_count));
      for (int i = 0; i < set.tile_count; ++i) {
        if (owners[size_t(i)] != me) continue;
        const std::string path = o.output + ".tile" + std::to_string(i) + ".tmp";
        cli::registerTemporary(path);
        wang::WangTileNdfReport rep;
        const bake::BakeStatus s =
            wang::bakeWangTileNdf(set, i, nopt, path, tile_meta_text, &tile_bytes[size_t(i)], &rep);
        std::remove(path.c_str());
        cli::unregisterTemporary(path);
        if (!s)
          throw Error(cli::exitCodeOf(s.error()), o.input + ": tile " + std::to_string(i) + ": " + s.error().message);
        addTile(totals, rep, tile_bytes[size_t(i)].size(), o.uncompressed);
        if (totals.levels != o.pyramid.options.levels)
          throw Error(cli::kExitRuntime, o.input + ": tile " + std::to_string(i) + " has " +
                                             std::to_string(totals.levels) + " levels, not the planned " +
                                             std::to_string(o.pyramid.options.levels));
        ++units;
        if (bar) bar->advance();
      }
    }
    const double ndf_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_ndf).count();
    if (o.shard.active()) {
      // The shard's partial: the common sections at their positions in every part, its own tiles'
      // assets at theirs; glintinfo merge copies them back in order.
      cli::ShardOutput part(t, o.output, o.shard.spec, o.tensor.zstd_level);
      const std::vector<wang::WangSection> common = cli::unwrap(wang::wangCommonSections(set, rec));
      for (const wang::WangSection& c : common)
        cli::check(part.partial().add(c.type, 0, c.bytes.data(), c.bytes.size(), /*common=*/true));
      for (int i = 0; i < set.tile_count; ++i) {
        if (owners[size_t(i)] != me) {
          part.partial().skip();
          continue;
        }
        cli::check(part.partial().add(format::kSectionWangTileNdf, uint64_t(i), tile_bytes[size_t(i)].data(),
                                      tile_bytes[size_t(i)].size()));
      }
      part.finish(meta, format::AssetKind::kWangTiles, units, uint64_t(set.tile_count));
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (t.common().json) {
        Json doc;
        doc["tool"] = "wangtile";
        doc["output"] = cli::baseName(o.output);
        doc["kind"] = "partial";
        doc["shard"] = {{"index", o.shard.spec.index}, {"count", o.shard.spec.count}};
        doc["units"] = units;
        doc["units_total"] = set.tile_count;
        doc["estimated_cost_share"] = double(units) / double(set.tile_count);
        doc["sections_held"] = part.partial().held();
        doc["positions"] = part.partial().positions();
        doc["file_bytes"] = part.bytesWritten();
        doc["seconds"] = seconds;
        t.printJson(doc);
      } else {
        t.info("wrote " + o.output + ": shard " + std::to_string(o.shard.spec.index) + "/" +
               std::to_string(o.shard.spec.count) + " of a wang-tiles asset, " + std::to_string(units) + " of " +
               std::to_string(set.tile_count) + " tiles, " + std::to_string(part.bytesWritten()) + " bytes in " +
               std::to_string(seconds) + " s");
      }
      return cli::kExitOk;
    }

    cli::ContainerOutput out(t, o.output, format::AssetKind::kWangTiles, o.tensor.zstd_level);
    if (bake::BakeStatus s = wang::writeWangSections(out.writer(), set, rec, tile_bytes); !s)
      throw Error(cli::exitCodeOf(s.error()), o.output + ": " + s.error().message);
    const uint64_t texel_bytes = format::wangTexelsBytes(rec);

    // The figures: seams, sizes, and what one baked map of a 16K x 16K surface would take at the
    // tiles' own bytes per texel of NDF (the extended squares overlap by the margins) plus its
    // float32 (n_x, n_y) flakes.
    const double T = double(set.tile_size), E = T + 2.0 * plan.margin;
    const double ndf_bytes_per_texel = double(totals.ndf_bytes) / (double(set.tile_count) * E * E);
    const double map16k = 16384.0 * 16384.0;
    const double map16k_bytes = map16k * (ndf_bytes_per_texel + 8.0);
    out.finish(meta);

    if (!o.atlas.empty()) {
      const bake::NormalMap atlas = wang::wangAtlas(set);
      if (bake::BakeStatus s = bake::writeNormalMap(o.atlas, atlas); !s)
        throw Error(cli::exitCodeOf(s.error()), s.error().message);
      t.addOutput(o.atlas);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double relative_error =
        totals.norm_squared > 0.0 ? std::sqrt(totals.error_squared / totals.norm_squared) : 0.0;
    if (!t.common().json) {
      char summary[256];
      std::snprintf(summary, sizeof(summary),
                    ": %d tiles of %d^2, seams %.2f deg mean (plain cut %.2f), %llu bytes, relative error %.4f, %.1f s",
                    set.tile_count, set.tile_size, set.seam.mean_degrees, set.plain_seam.mean_degrees,
                    static_cast<unsigned long long>(out.bytesWritten()), relative_error, seconds);
      t.info("wrote " + o.output + summary);
      return cli::kExitOk;
    }
    Json doc;
    doc["tool"] = "wangtile";
    doc["input"] = cli::baseName(o.input);
    doc["output"] = cli::baseName(o.output);
    doc["atlas"] = o.atlas.empty() ? Json(nullptr) : Json(cli::baseName(o.atlas));
    doc["example"] = {{"width", example.width}, {"height", example.height}};
    doc["parameters"] = params;
    doc["tile_count"] = set.tile_count;
    doc["tile_size"] = set.tile_size;
    doc["colors"] = set.colors;
    doc["seam"] = seamJson(set.seam);
    doc["plain_seam"] = seamJson(set.plain_seam);
    doc["max_sigma"] = plan.max_sigma;
    doc["flakes_up_to"] = plan.flakes_up_to;
    doc["pyramid_from"] = plan.pyramid_from;
    doc["level_sigmas"] = totals.level_sigmas;
    doc["relative_error"] = o.uncompressed ? Json(nullptr) : Json(relative_error);
    doc["max_tile_error"] = o.uncompressed ? Json(nullptr) : Json(totals.max_tile_error);
    doc["sizes"] = {{"file_bytes", out.bytesWritten()},
                    {"texel_bytes", texel_bytes},
                    {"tile_ndf_bytes", totals.ndf_bytes},
                    {"raw_ndf_bytes", totals.raw_bytes},
                    {"map_16k_estimate_bytes", map16k_bytes}};
    doc["seconds"] = {{"tiles", tile_seconds}, {"ndf", ndf_seconds}, {"total", seconds}};
    t.printJson(doc);
    return cli::kExitOk;
  });
}
