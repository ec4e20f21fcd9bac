// SPDX-License-Identifier: Apache-2.0
// Procedural maps: kind names, parameter validation, dispatch to the generators, and the
// statistics the tests and the mapgen tool report.
#include <glintbake/bake/mapgen/mapgen.h>

#include "mapgen/generators.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace glintbake::bake {
namespace {

constexpr MapKind kAllKinds[] = {MapKind::kFlat, MapKind::kBeckmann, MapKind::kBrushed, MapKind::kScratches,
                                 MapKind::kFlakes};

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Fails with "<name> must be in [lo, hi] (or (lo, hi]), got v"; NaN never passes.
BakeStatus checkRange(const char* name, double v, double lo, double hi, bool open_low) {
  const bool ok = (open_low ? v > lo : v >= lo) && v <= hi;
  if (ok) return okStatus();
  return makeError(ErrorCode::kBadArgument, std::string(name) + " must be in " + (open_low ? "(" : "[") + number(lo) +
                                                ", " + number(hi) + "], got " + number(v));
}

}  // namespace

const char* mapKindString(MapKind kind) {
  switch (kind) {
    case MapKind::kFlat:
      return "flat";
    case MapKind::kBeckmann:
      return "beckmann";
    case MapKind::kBrushed:
      return "brushed";
    case MapKind::kScratches:
      return "scratches";
    case MapKind::kFlakes:
      return "flakes";
  }
  return "flat";
}

bool mapKindFromString(const std::string& name, MapKind* kind) {
  for (MapKind k : kAllKinds) {
    if (name == mapKindString(k)) {
      if (kind != nullptr) *kind = k;
      return true;
    }
  }
  return false;
}

std::string mapKindList() {
  std::string list;
  for (MapKind k : kAllKinds) {
    if (!list.empty()) list += ", ";
    list += mapKindString(k);
  }
  return list;
}

double effectiveCell(MapKind kind, const MapParams& params) {
  if (params.cell > 0.0) return params.cell;
  if (kind == MapKind::kFlakes) return std::min(kDefaultFlakeCell, double(std::max(1, params.size)));
  return std::min(kDefaultGaussianCell, std::max(0.5, params.size / 4.0));
}

BakeStatus validateMapParams(MapKind kind, const MapParams& params) {
  if (params.size < 1) {
    return makeError(ErrorCode::kBadArgument, "size must be >= 1, got " + std::to_string(params.size));
  }
  const double size = params.size;
  const double cell = effectiveCell(kind, params);
  BakeStatus status = okStatus();
  switch (kind) {
    case MapKind::kFlat:
      break;
    case MapKind::kBeckmann:
      status = checkRange("alpha", params.alpha, 0.0, 4.0, true);
      if (status) status = checkRange("cell", cell, 0.0, size / 2.0, true);
      break;
    case MapKind::kBrushed:
      status = checkRange("alpha-x", params.alpha_x, 0.0, 4.0, true);
      if (status) status = checkRange("alpha-y", params.alpha_y, 0.0, 4.0, true);
      if (status) status = checkRange("cell", cell, 0.0, size / 2.0, true);
      break;
    case MapKind::kScratches:
      status = checkRange("density", params.density, 0.0, 1000.0, false);
      if (status) status = checkRange("width", params.width, 0.0, std::min(256.0, size / 4.0), true);
      if (status) status = checkRange("slope", params.scratch_slope, 0.0, 10.0, true);
      break;
    case MapKind::kFlakes:
      status = checkRange("cone", params.cone_degrees, 0.0, 89.0, false);
      if (status) status = checkRange("cell", cell, 1.0, size, false);
      break;
  }
  return status;
}

NormalMap generateMap(MapKind kind, const MapParams& params) {
  GLINTBAKE_CHECK(validateMapParams(kind, params).ok());
  const double cell = effectiveCell(kind, params);
  constexpr double kSqrtHalf = 0.70710678118654752440;
  switch (kind) {
    case MapKind::kBeckmann:
      return mapgen::gaussianSurface(params.size, params.seed, cell, cell, params.alpha * kSqrtHalf,
                                     params.alpha * kSqrtHalf);
    case MapKind::kBrushed: {
      // Slope std scales as 1 / kernel std, so this elongation makes one height field carry both
      // target slopes; the cap keeps the kernel well inside the period.
      const double along = std::min(cell * params.alpha_y / params.alpha_x, std::max(cell, params.size / 4.0));
      return mapgen::gaussianSurface(params.size, params.seed, along, cell, params.alpha_x * kSqrtHalf,
                                     params.alpha_y * kSqrtHalf);
    }
    case MapKind::kScratches:
      return mapgen::scratches(params);
    case MapKind::kFlakes:
      return mapgen::flakes(params, cell);
    case MapKind::kFlat:
      break;
  }
  NormalMap map;
  map.width = params.size;
  map.height = params.size;
  map.wrap = Wrap::kRepeat;
  map.normals.assign(size_t(params.size) * size_t(params.size) * 3, 0.0f);
  for (size_t i = 2; i < map.normals.size(); i += 3) map.normals[i] = 1.0f;
  return map;
}

MapStatistics measureMap(const NormalMap& map) {
  MapStatistics stats;
  if (map.width <= 0 || map.height <= 0) return stats;
  constexpr double kMinZ = 1e-6;
  constexpr double kDegrees = 57.295779513082320877;

  // Per-row partial sums reduced in row order: two passes (mean, then squared deviations) for
  // accuracy, both deterministic whatever the scheduling.
  struct Row {
    double n[3] = {0.0, 0.0, 0.0};
    double slope[2] = {0.0, 0.0};
    double dev2[2] = {0.0, 0.0};
    int64_t sloped = 0;
    double min_z = 1.0;
  };
  std::vector<Row> rows(size_t(map.height));
  tbb::parallel_for(tbb::blocked_range<int>(0, map.height), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y != range.end(); ++y) {
      Row& row = rows[size_t(y)];
      for (int x = 0; x < map.width; ++x) {
        const float* n = map.at(x, y);
        for (int k = 0; k < 3; ++k) row.n[k] += n[k];
        row.min_z = std::min(row.min_z, double(n[2]));
        if (n[2] > kMinZ) {
          row.slope[0] += -double(n[0]) / n[2];
          row.slope[1] += -double(n[1]) / n[2];
          ++row.sloped;
        }
      }
    }
  });
  double sum_n[3] = {0.0, 0.0, 0.0}, sum_slope[2] = {0.0, 0.0}, min_z = 1.0;
  int64_t sloped = 0;
  for (const Row& row : rows) {
    for (int k = 0; k < 3; ++k) sum_n[k] += row.n[k];
    for (int k = 0; k < 2; ++k) sum_slope[k] += row.slope[k];
    sloped += row.sloped;
    min_z = std::min(min_z, row.min_z);
  }
  stats.texels = int64_t(map.width) * map.height;
  for (int k = 0; k < 3; ++k) stats.mean_normal[k] = sum_n[k] / double(stats.texels);
  if (sloped > 0) {
    for (int k = 0; k < 2; ++k) stats.slope_mean[k] = sum_slope[k] / double(sloped);
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, map.height), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y != range.end(); ++y) {
      Row& row = rows[size_t(y)];
      for (int x = 0; x < map.width; ++x) {
        const float* n = map.at(x, y);
        if (n[2] <= kMinZ) continue;
        const double dx = -double(n[0]) / n[2] - stats.slope_mean[0];
        const double dy = -double(n[1]) / n[2] - stats.slope_mean[1];
        row.dev2[0] += dx * dx;
        row.dev2[1] += dy * dy;
      }
    }
  });
  if (sloped > 0) {
    double dev2[2] = {0.0, 0.0};
    for (const Row& row : rows) {
      dev2[0] += row.dev2[0];
      dev2[1] += row.dev2[1];
    }
    for (int k = 0; k < 2; ++k) stats.slope_std[k] = std::sqrt(dev2[k] / double(sloped));
  }
  stats.max_angle_degrees = std::acos(std::clamp(min_z, -1.0, 1.0)) * kDegrees;
  return stats;
}

}  // namespace glintbake::bake
