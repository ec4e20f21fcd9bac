// SPDX-License-Identifier: Apache-2.0
// Private: enumeration of the flakes a footprint sees, shared by every reference entry point so
// that all of them sum the same lobes in the same order.
#pragma once

#include <glintbake/reference/pndf.h>

#include <cmath>
#include <cstdint>

namespace glintbake::reference::detail {

// Floor modulo for a possibly negative index.
inline int64_t floorMod(int64_t i, int64_t n) {
  const int64_t m = i % n;
  return m < 0 ? m + n : m;
}

// Truncation radius in texels of a footprint (pndf.h, kTruncationSigmas).
inline double truncationRadius(const FlakeSet& set, const Footprint& fp) {
  return kTruncationSigmas * std::sqrt(set.sigma_h * set.sigma_h + fp.sigma * fp.sigma);
}

// Calls fn(flake, ux, uy) for every flake (with wrap=repeat: every periodic image of every flake)
// whose position (ux, uy) lies within the truncation radius of the footprint centre (closed disk).
// Order: fine row, then fine column, of the unwrapped fine grid; independent of threads.
template <typename Fn>
void forEachFlakeInFootprint(const FlakeSet& set, const Footprint& fp, Fn&& fn) {
  const double radius = truncationRadius(set, fp);
  const double radius2 = radius * radius;
  const double rate = double(set.rate);
  const int64_t fine_w = set.fineWidth();
  const int64_t fine_h = set.fineHeight();
  // Fine-grid points (index + 0.5) / rate inside [centre - radius, centre + radius] on each axis.
  int64_t fc_lo = int64_t(std::ceil((fp.x - radius) * rate - 0.5));
  int64_t fc_hi = int64_t(std::floor((fp.x + radius) * rate - 0.5));
  int64_t fr_lo = int64_t(std::ceil((fp.y - radius) * rate - 0.5));
  int64_t fr_hi = int64_t(std::floor((fp.y + radius) * rate - 0.5));
  if (set.wrap == bake::Wrap::kClamp) {
    // No flakes outside the map.
    fc_lo = fc_lo < 0 ? 0 : fc_lo;
    fr_lo = fr_lo < 0 ? 0 : fr_lo;
    fc_hi = fc_hi > fine_w - 1 ? fine_w - 1 : fc_hi;
    fr_hi = fr_hi > fine_h - 1 ? fine_h - 1 : fr_hi;
  }
  for (int64_t fr = fr_lo; fr <= fr_hi; ++fr) {
    const double uy = (double(fr) + 0.5) / rate;
    const double dy = uy - fp.y;
    if (dy * dy > radius2) continue;
    const int64_t base_row = floorMod(fr, fine_h);
    for (int64_t fc = fc_lo; fc <= fc_hi; ++fc) {
      const double ux = (double(fc) + 0.5) / rate;
      const double dx = ux - fp.x;
      if (dx * dx + dy * dy > radius2) continue;
      fn(set.at(int(floorMod(fc, fine_w)), int(base_row)), ux, uy);
    }
  }
}

}  // namespace glintbake::reference::detail
