// SPDX-License-Identifier: Apache-2.0
// Flake maps: periodic Voronoi cells, one normal per cell drawn uniformly (in solid angle) from a
// cone around z. Nearest sites are found through a uniform grid of bins on the torus.
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

// Shortest signed difference on a circle of circumference n.
inline double torusDelta(double d, double n) { return d - n * std::round(d / n); }

}  // namespace

NormalMap flakes(const MapParams& params, double cell) {
  const int n = params.size;
  const double nd = double(n);
  const int64_t site_count = std::max<int64_t>(1, std::llround(nd * nd / (cell * cell)));
  const double cos_cone = std::cos(params.cone_degrees * kPi / 180.0);

  std::vector<double> site_x(static_cast<size_t>(site_count)), site_y(static_cast<size_t>(site_count));
  std::vector<float> site_normal(size_t(site_count) * 3);
  for (int64_t i = 0; i < site_count; ++i) {
    const uint64_t index = uint64_t(i);
    site_x[size_t(i)] = uniform01(params.seed, kStreamSites, index, 0) * nd;
    site_y[size_t(i)] = uniform01(params.seed, kStreamSites, index, 1) * nd;
    // Uniform on the spherical cap: cos(theta) uniform in [cos(cone), 1].
    const double cos_t = 1.0 - uniform01(params.seed, kStreamSiteNormals, index, 0) * (1.0 - cos_cone);
    const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
    const double phi = 2.0 * kPi * uniform01(params.seed, kStreamSiteNormals, index, 1);
    float* sn = &site_normal[size_t(i) * 3];
    sn[0] = float(sin_t * std::cos(phi));
    sn[1] = float(sin_t * std::sin(phi));
    sn[2] = float(cos_t);
  }

  // Bins of about one cell; each lists its sites in increasing index order.
  const int bins = std::max(1, int(nd / cell));
  const double bin_size = nd / bins;
  std::vector<std::vector<int64_t>> grid(size_t(bins) * size_t(bins));
  for (int64_t i = 0; i < site_count; ++i) {
    const int bx = std::min(bins - 1, int(site_x[size_t(i)] / bin_size));
    const int by = std::min(bins - 1, int(site_y[size_t(i)] / bin_size));
    grid[size_t(by) * size_t(bins) + size_t(bx)].push_back(i);
  }

  NormalMap map;
  map.width = n;
  map.height = n;
  map.wrap = Wrap::kRepeat;
  map.normals.resize(size_t(n) * size_t(n) * 3);
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& rows) {
    for (int r = rows.begin(); r != rows.end(); ++r) {
      for (int c = 0; c < n; ++c) {
        const double x = c + 0.5, y = r + 0.5;
        const int bx = std::min(bins - 1, int(x / bin_size)), by = std::min(bins - 1, int(y / bin_size));
        double best = std::numeric_limits<double>::infinity();
        int64_t best_site = -1;
        // Rings of bins at growing Chebyshev distance. A site in ring k + 1 is at least k bins
        // away, so the search stops once the best distance is within that; ties go to the
        // lower site index, so the answer does not depend on the visiting order.
        for (int ring = 0;; ++ring) {
          for (int dy = -ring; dy <= ring; ++dy) {
            for (int dx = -ring; dx <= ring; ++dx) {
              if (std::max(std::abs(dx), std::abs(dy)) != ring) continue;
              const int gx = ((bx + dx) % bins + bins) % bins, gy = ((by + dy) % bins + bins) % bins;
              for (int64_t s : grid[size_t(gy) * size_t(bins) + size_t(gx)]) {
                const double ddx = torusDelta(site_x[size_t(s)] - x, nd);
                const double ddy = torusDelta(site_y[size_t(s)] - y, nd);
                const double d2 = ddx * ddx + ddy * ddy;
                if (d2 < best || (d2 == best && s < best_site)) {
                  best = d2;
                  best_site = s;
                }
              }
            }
          }
          const double reach = ring * bin_size;
          if ((best_site >= 0 && best <= reach * reach) || 2 * ring + 1 >= bins) break;
        }
        const float* sn = &site_normal[size_t(best_site) * 3];
        float* out = map.at(c, r);
        out[0] = sn[0];
        out[1] = sn[1];
        out[2] = sn[2];
      }
    }
  });
  return map;
}

}  // namespace glintbake::bake::mapgen
