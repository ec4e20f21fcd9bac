// SPDX-License-Identifier: Apache-2.0
// Argument checks every NDF and BRDF query shares (internal to the runtime): a footprint, an
// s-plane point, an s-plane rectangle and a direction.
#pragma once

#include <glintbake/runtime/brdf.h>
#include <glintbake/runtime/runtime.h>

#include <cmath>

namespace glintbake::runtime {

// Footprint arguments every query accepts: finite, sigma >= 0, position within +-1e15 texels.
inline bool validFootprint(const Footprint& fp) {
  return std::isfinite(fp.x) && std::isfinite(fp.y) && std::isfinite(fp.sigma) && fp.sigma >= 0.0 &&
         std::fabs(fp.x) < 1e15 && std::fabs(fp.y) < 1e15;
}

inline bool finitePoint(const SPoint& s) { return std::isfinite(s.x) && std::isfinite(s.y); }

// Finite corners with x1 > x0 and y1 > y0.
inline bool validRect(const SRect& r) {
  return std::isfinite(r.x0) && std::isfinite(r.x1) && std::isfinite(r.y0) && std::isfinite(r.y1) && r.x1 > r.x0 &&
         r.y1 > r.y0;
}

inline bool finiteVec3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace glintbake::runtime
