// SPDX-License-Identifier: Apache-2.0
// Scratched maps: a flat base with straight V-groove scratches, rasterised with 4x4 sub-samples
// per texel on the torus (the map is tileable).
#include "mapgen/generators.h"
#include "mapgen/random.h"

#include <glintbake/format/numbers.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace glintbake::bake::mapgen {
namespace {

constexpr int kSubSamples = 4;  // per texel side
constexpr double kMinLengthFraction = 0.1, kMaxLengthFraction = 0.5;

struct Segment {
  double cx, cy;  // centre, texels (image coordinates: x right, y down)
  double dx, dy;  // unit direction along the scratch
  double half_length;
};

}  // namespace

NormalMap scratches(const MapParams& params) {
  const int n = params.size;
  const size_t texels = size_t(n) * size_t(n);
  const double area_thousands = double(n) * double(n) / 1000.0;
  const int64_t count = int64_t(std::llround(params.density * area_thousands));
  const double half_width = 0.5 * params.width;
  const double wall = params.scratch_slope;

  // Height gradient in image coordinates (d/dx right, d/drow down), summed over grooves.
  std::vector<double> grad_x(texels, 0.0), grad_row(texels, 0.0);
  const double inv_samples = 1.0 / double(kSubSamples * kSubSamples);

  // Serial in segment order: overlapping grooves add, and the order of additions is fixed.
  for (int64_t i = 0; i < count; ++i) {
    const uint64_t index = uint64_t(i);
    Segment s;
    s.cx = uniform01(params.seed, kStreamScratches, index, 0) * n;
    s.cy = uniform01(params.seed, kStreamScratches, index, 1) * n;
    const double angle = uniform01(params.seed, kStreamScratches, index, 2) * kPi;
    s.dx = std::cos(angle);
    s.dy = std::sin(angle);
    const double fraction = kMinLengthFraction + (kMaxLengthFraction - kMinLengthFraction) *
                                                     uniform01(params.seed, kStreamScratches, index, 3);
    s.half_length = 0.5 * fraction * n;
    // Across-groove direction; the groove floor is the centre line, walls rise to either side.
    const double px = -s.dy, py = s.dx;

    // Texels whose square can reach the groove, row by row: the x extent of the groove rectangle
    // clipped to the row's band, plus a texel of margin. The span stays below one period
    // (validated width <= size / 4 and length <= size / 2), so no texel is visited twice per groove.
    const double hx = s.dx * s.half_length, hy = s.dy * s.half_length;
    const double wx = px * half_width, wy = py * half_width;
    const double corner_x[4] = {s.cx - hx - wx, s.cx + hx - wx, s.cx + hx + wx, s.cx - hx + wx};
    const double corner_y[4] = {s.cy - hy - wy, s.cy + hy - wy, s.cy + hy + wy, s.cy - hy + wy};
    const double y_min = *std::min_element(corner_y, corner_y + 4);
    const double y_max = *std::max_element(corner_y, corner_y + 4);
    for (int r = int(std::floor(y_min)) - 1; r <= int(std::ceil(y_max)); ++r) {
      const double band0 = r - 1.0, band1 = r + 2.0;  // the row's band with a texel of margin
      double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo;
      for (int e = 0; e < 4; ++e) {
        const double ax = corner_x[e], ay = corner_y[e];
        const double bx = corner_x[(e + 1) % 4], by = corner_y[(e + 1) % 4];
        if (std::max(ay, by) < band0 || std::min(ay, by) > band1) continue;
        double t0 = 0.0, t1 = 1.0;
        if (ay != by) {
          const double ta = (band0 - ay) / (by - ay), tb = (band1 - ay) / (by - ay);
          t0 = std::max(0.0, std::min(ta, tb));
          t1 = std::min(1.0, std::max(ta, tb));
        }
        for (double t : {t0, t1}) {
          const double x = ax + t * (bx - ax);
          x_lo = std::min(x_lo, x);
          x_hi = std::max(x_hi, x);
        }
      }
      if (!(x_lo <= x_hi)) continue;
      for (int c = int(std::floor(x_lo)) - 1; c <= int(std::ceil(x_hi)); ++c) {
        double gx = 0.0, grow = 0.0;
        for (int j = 0; j < kSubSamples; ++j) {
          for (int k = 0; k < kSubSamples; ++k) {
            const double ux = c + (k + 0.5) / kSubSamples - s.cx;
            const double uy = r + (j + 0.5) / kSubSamples - s.cy;
            const double along = ux * s.dx + uy * s.dy;
            const double across = ux * px + uy * py;
            if (std::abs(along) > s.half_length || std::abs(across) >= half_width) continue;
            // V profile h = wall * (|across| - half_width): gradient wall * sign(across) * p.
            const double sign = across >= 0.0 ? 1.0 : -1.0;
            gx += wall * sign * px;
            grow += wall * sign * py;
          }
        }
        if (gx == 0.0 && grow == 0.0) continue;
        const size_t t = size_t(((r % n) + n) % n) * size_t(n) + size_t(((c % n) + n) % n);
        grad_x[t] += gx * inv_samples;
        grad_row[t] += grow * inv_samples;
      }
    }
  }

  NormalMap map;
  map.width = n;
  map.height = n;
  map.wrap = Wrap::kRepeat;
  map.normals.resize(texels * 3);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, texels), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t t = range.begin(); t != range.end(); ++t) {
      // Tangent y points up (against the rows): dh/dy_up = -dh/drow.
      slopeToNormal(grad_x[t], -grad_row[t], &map.normals[t * 3]);
    }
  });
  return map;
}

}  // namespace glintbake::bake::mapgen
