// SPDX-License-Identifier: Apache-2.0
// The in-memory normal map: wrap-mode texel fetch, and the renormalisation and repair shared by
// every way a map enters the library (files, raw pixels, generated maps).
#include <glintbake/bake/io/normal_map.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace glintbake::bake {

const char* encodingString(Encoding e) {
  switch (e) {
    case Encoding::kAuto:
      return "auto";
    case Encoding::kUnorm:
      return "unorm";
    case Encoding::kSnorm:
      return "snorm";
  }
  return "auto";
}

const char* wrapString(Wrap w) {
  switch (w) {
    case Wrap::kRepeat:
      return "repeat";
    case Wrap::kClamp:
      return "clamp";
  }
  return "repeat";
}

const float* NormalMap::fetch(int x, int y) const {
  if (wrap == Wrap::kRepeat) {
    x %= width;
    y %= height;
    if (x < 0) x += width;
    if (y < 0) y += height;
  } else {
    x = std::clamp(x, 0, width - 1);
    y = std::clamp(y, 0, height - 1);
  }
  return at(x, y);
}

namespace {

bool isFinite3(const float* n) { return std::isfinite(n[0]) && std::isfinite(n[1]) && std::isfinite(n[2]); }

// Per-row tallies, reduced in row order afterwards so the report does not depend on scheduling.
struct RowTally {
  int64_t far_from_unit = 0;
  int64_t nz_nonpositive = 0;
  int64_t nonfinite = 0;
  int64_t first_nonfinite_x = -1;
  double length_sum = 0.0;
  int64_t finite = 0;
};

}  // namespace

BakeStatus normaliseNormals(NormalMap* map, const IngestOptions& options, IngestReport* report) {
  GLINTBAKE_CHECK(map != nullptr);
  GLINTBAKE_CHECK(map->width > 0 && map->height > 0);
  GLINTBAKE_CHECK(map->normals.size() == size_t(map->width) * size_t(map->height) * 3);

  const int width = map->width;
  std::vector<RowTally> rows(size_t(map->height));
  const double tolerance = options.unit_tolerance;
  const bool fix = options.fix_nonfinite;

  tbb::parallel_for(tbb::blocked_range<int>(0, map->height), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y != range.end(); ++y) {
      RowTally& tally = rows[size_t(y)];
      for (int x = 0; x < width; ++x) {
        float* n = map->at(x, y);
        if (!isFinite3(n)) {
          if (tally.nonfinite == 0) tally.first_nonfinite_x = x;
          ++tally.nonfinite;
          if (fix) {
            n[0] = 0.0f;
            n[1] = 0.0f;
            n[2] = 1.0f;
          }
          continue;
        }
        // Lengths in double: 8-bit maps sit far from unit length and the statistic should not
        // depend on float rounding.
        const double nx = n[0], ny = n[1], nz = n[2];
        const double length = std::sqrt(nx * nx + ny * ny + nz * nz);
        tally.length_sum += length;
        ++tally.finite;
        if (std::abs(length - 1.0) > tolerance) ++tally.far_from_unit;
        if (nz <= 0.0) {
          // Below or on the horizon: keep the azimuth of (n_x, n_y) and put the normal on the
          // horizon (|s| = 1), the closest point of the upper hemisphere. A zero projection has no
          // azimuth to keep and becomes the geometric normal.
          ++tally.nz_nonpositive;
          const double s = std::sqrt(nx * nx + ny * ny);
          if (s > 0.0) {
            n[0] = float(nx / s);
            n[1] = float(ny / s);
            n[2] = 0.0f;
          } else {
            n[0] = 0.0f;
            n[1] = 0.0f;
            n[2] = 1.0f;
          }
          continue;
        }
        n[0] = float(nx / length);
        n[1] = float(ny / length);
        n[2] = float(nz / length);
      }
    }
  });

  RowTally total;
  int64_t first_row = -1;
  for (size_t y = 0; y < rows.size(); ++y) {
    const RowTally& r = rows[y];
    if (r.nonfinite > 0 && first_row < 0) {
      first_row = int64_t(y);
      total.first_nonfinite_x = r.first_nonfinite_x;
    }
    total.far_from_unit += r.far_from_unit;
    total.nz_nonpositive += r.nz_nonpositive;
    total.nonfinite += r.nonfinite;
    total.length_sum += r.length_sum;
    total.finite += r.finite;
  }

  if (report != nullptr) {
    report->texels = int64_t(width) * map->height;
    report->far_from_unit = total.far_from_unit;
    report->nz_nonpositive = total.nz_nonpositive;
    report->nonfinite = total.nonfinite;
    report->mean_length = total.finite > 0 ? total.length_sum / double(total.finite) : 0.0;
  }
  if (total.nonfinite > 0 && !fix) {
    return makeError(ErrorCode::kInvalidInput,
                     std::to_string(total.nonfinite) + " texel(s) hold NaN or Inf, the first at column " +
                         std::to_string(total.first_nonfinite_x) + ", row " + std::to_string(first_row) +
                         " (--fix-nonfinite replaces them by (0,0,1))");
  }
  return okStatus();
}

Result<NormalMap> normalMapFromPixels(int width, int height, int channels, const float* data,
                                      const IngestOptions& options, IngestReport* report) {
  if (width <= 0 || height <= 0) {
    return makeError(ErrorCode::kInvalidInput,
                     "empty map (" + std::to_string(width) + "x" + std::to_string(height) + ")");
  }
  if (width > options.max_size || height > options.max_size) {
    return makeError(ErrorCode::kInvalidInput, "map size " + std::to_string(width) + "x" + std::to_string(height) +
                                                   " exceeds the limit of " + std::to_string(options.max_size) +
                                                   " texels per side (raise it with --max-size)");
  }
  if (channels < 2 || channels > 4) {
    return makeError(ErrorCode::kInvalidInput, "unsupported channel count " + std::to_string(channels) +
                                                   " (expected 2 (XY), 3 (RGB) or 4 (RGBA))");
  }
  GLINTBAKE_CHECK(data != nullptr);

  NormalMap map;
  map.width = width;
  map.height = height;
  map.wrap = options.wrap;
  try {
    map.normals.resize(size_t(width) * size_t(height) * 3);
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime,
                     "out of memory for a " + std::to_string(width) + "x" + std::to_string(height) + " map");
  }
  const size_t texels = size_t(width) * size_t(height);
  const float sign_y = options.flip_green ? -1.0f : 1.0f;
  for (size_t i = 0; i < texels; ++i) {
    const float* p = data + i * size_t(channels);
    float* n = &map.normals[i * 3];
    n[0] = p[0];
    n[1] = sign_y * p[1];
    if (channels == 2) {
      // XY maps store the projected normal; z is the upper-hemisphere completion.
      const float r2 = p[0] * p[0] + p[1] * p[1];
      n[2] = std::isfinite(r2) ? std::sqrt(std::max(0.0f, 1.0f - r2)) : r2;
    } else {
      n[2] = p[2];
    }
  }

  IngestReport local;
  IngestReport* r = report != nullptr ? report : &local;
  r->file_format.clear();
  r->pixel_type = "float";
  r->channels_in = channels;
  r->encoding_used = Encoding::kSnorm;
  r->content_hash.clear();
  BakeStatus status = normaliseNormals(&map, options, r);
  if (!status) return status.error();
  return map;
}

}  // namespace glintbake::bake
