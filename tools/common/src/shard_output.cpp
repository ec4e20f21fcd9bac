// SPDX-License-Identifier: Apache-2.0
#include <glintbake/cli/shard_output.h>
#include <glintbake/format/kinds/partial.h>

#include <algorithm>
#include <cmath>

namespace glintbake::cli {

void addShardOption(CLI::App& app, ShardCliOptions& shard) {
  app.add_option("--shard", shard.text,
                 "Bake shard I of N (0-based) into a partial container; glintinfo merge joins the N parts into "
                 "the asset, byte-identical to the one-machine bake");
}

void resolveShardOption(ShardCliOptions& shard) {
  if (!shard.active()) return;
  bake::Result<bake::shard::ShardSpec> spec = bake::shard::parseShardSpec(shard.text);
  if (!spec) throw Error(kExitBadArguments, spec.error().message);
  shard.spec = spec.value();
}

PyramidShardPlan::PyramidShardPlan(const bake::NormalMap& map, const bake::ndf::PyramidOptions& options, bool flakes,
                                   int shards) {
  const int max_levels = options.levels > 0 ? options.levels : bake::ndf::kMaxPyramidLevels;
  const double map_w = double(map.width), map_h = double(map.height);
  const double rate2 = double(options.rate) * double(options.rate);
  for (int level = 0; level < max_levels; ++level) {
    const bake::ndf::LevelGeometry g =
        bake::ndf::levelGeometry(map.width, map.height, options, level, map.wrap == bake::Wrap::kRepeat);
    level_base_.push_back(costs_.size());
    level_regions_.push_back(size_t(g.regions_x) * size_t(g.regions_y));
    const double extent = 2.0 * options.splat.footprint_truncation * g.sigma;
    const double per_image = std::min(extent, map_w) * std::min(extent, map_h) * rate2 + 1.0;
    for (int r = 0; r < g.regions_x * g.regions_y; ++r) {
      const int rx = r % g.regions_x, ry = r / g.regions_x;
      const int cw = std::min(options.region_size, g.grid_width - rx * options.region_size);
      const int ch = std::min(options.region_size, g.grid_height - ry * options.region_size);
      costs_.push_back(double(cw) * double(ch) * per_image);
    }
    if (options.levels == 0 && g.grid_width == 1 && g.grid_height == 1) break;
  }
  // Each level is dealt out on its own (longest first), and its busiest share goes to the shard
  // with the least work so far: the automatic level count may stop at any level, so every level
  // the bake reaches must be balanced, not just the sum over the levels it might reach.
  owners_.assign(costs_.size(), 0);
  std::vector<double> total(static_cast<size_t>(shards), 0.0);
  for (size_t l = 0; l < level_base_.size(); ++l) {
    const std::vector<double> costs(costs_.begin() + long(level_base_[l]),
                                    costs_.begin() + long(level_base_[l] + level_regions_[l]));
    const std::vector<int> local = bake::shard::assignShards(costs, shards);
    std::vector<double> level_load(static_cast<size_t>(shards), 0.0);
    for (size_t u = 0; u < local.size(); ++u) level_load[size_t(local[u])] += costs[u];
    const size_t n = static_cast<size_t>(shards);
    std::vector<int> by_level(n), by_total(n);
    for (int i = 0; i < shards; ++i) by_level[size_t(i)] = by_total[size_t(i)] = i;
    std::stable_sort(by_level.begin(), by_level.end(),
                     [&](int a, int b) { return level_load[size_t(a)] > level_load[size_t(b)]; });
    std::stable_sort(by_total.begin(), by_total.end(),
                     [&](int a, int b) { return total[size_t(a)] < total[size_t(b)]; });
    std::vector<int> to_global(n);
    for (int k = 0; k < shards; ++k) to_global[size_t(by_level[size_t(k)])] = by_total[size_t(k)];
    for (size_t u = 0; u < local.size(); ++u) {
      const int g = to_global[size_t(local[u])];
      owners_[level_base_[l] + u] = g;
      total[size_t(g)] += costs[u];
    }
  }
  if (flakes) {  // one copy of the map, compressed: to the least loaded shard
    costs_.push_back(map_w * map_h);
    const int least = int(std::min_element(total.begin(), total.end()) - total.begin());
    owners_.push_back(least);
    flakes_owner_ = least;
  }
}

int PyramidShardPlan::owner(int level, int region) const {
  if (level < 0 || size_t(level) >= level_base_.size()) return -1;
  if (region < 0 || size_t(region) >= level_regions_[size_t(level)]) return -1;
  return owners_[level_base_[size_t(level)] + size_t(region)];
}

uint64_t PyramidShardPlan::unitsOf(int shard) const {
  return uint64_t(std::count(owners_.begin(), owners_.end(), shard));
}

double PyramidShardPlan::costOf(int shard) const {
  double c = 0.0;
  for (size_t u = 0; u < owners_.size(); ++u) c += owners_[u] == shard ? costs_[u] : 0.0;
  return c;
}

std::function<bool(int, int)> PyramidShardPlan::filter(int shard) const {
  return [this, shard](int level, int region) { return owner(level, region) == shard; };
}

ShardOutput::ShardOutput(Tool& tool, const std::string& path, const bake::shard::ShardSpec& spec, int zstd_level)
    : tool_(tool),
      spec_(spec),
      zstd_level_(zstd_level),
      out_(tool, path, format::AssetKind::kPartial, 3),
      partial_(out_.writer(), zstd_level) {}

void ShardOutput::addUnit(uint64_t unit, const void* data, size_t size) {
  out_.addSection(format::kSectionShardUnit, unit, data, size);
}

void ShardOutput::finish(const Json& asset_metadata, format::AssetKind asset_kind, uint64_t units, uint64_t units_total,
                         const Json& assembly) {
  const std::string text = asset_metadata.dump();
  out_.addSection(format::kSectionShardMetadata, 0, text.data(), text.size());
  Json params = asset_metadata.value("parameters", Json::object());
  params["shard"] = std::to_string(spec_.index) + "/" + std::to_string(spec_.count);
  Json meta = tool_.makeMetadata(format::AssetKind::kPartial, params);
  Json asset;
  asset["asset_kind"] = format::assetKindString(asset_kind);
  asset["shard"] = spec_.index;
  asset["shards"] = spec_.count;
  asset["positions"] = partial_.positions();
  asset["sections_held"] = partial_.held();
  asset["units"] = units;
  asset["units_total"] = units_total;
  asset["zstd_level"] = zstd_level_;
  asset["asset_metadata_hash"] = format::hash128Hex(text.data(), text.size());
  if (!assembly.is_null()) asset["assembly"] = assembly;
  meta["asset"] = asset;
  out_.finish(meta);
}

}  // namespace glintbake::cli
