// SPDX-License-Identifier: Apache-2.0
// Query helpers shared by every pyramid-shaped asset (ndf-pyramid, tensor-ndf; formats/SPEC.md
// 10.1), internal to the runtime: the footprint argument check, the bin of an s-plane point, and
// the trilinear footprint blend (glintbake/format/kinds/ndf_pyramid_blend.h).
#pragma once

#include <glintbake/format/kinds/ndf_pyramid_blend.h>
#include <glintbake/runtime/runtime.h>

#include "query_args.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace glintbake::runtime {

// Column i and row j of the bin of an R x R NDF image (bin side 2 / res, inv_bin = res / 2)
// holding s (row 0 at s_y = +1), false outside [-1, 1]^2; ndfBinOf gives the index j * res + i, or
// -1 outside. Every query that locates a bin (pdf, eval, sample's own check) goes through here.
inline bool ndfBinCoords(double sx, double sy, int res, double inv_bin, int* i, int* j) {
  if (!(sx >= -1.0 && sx <= 1.0 && sy >= -1.0 && sy <= 1.0)) return false;
  *i = std::min(res - 1, int((sx + 1.0) * inv_bin));
  *j = std::min(res - 1, int((1.0 - sy) * inv_bin));
  return true;
}
inline int ndfBinOf(double sx, double sy, int res, double inv_bin) {
  int i, j;
  return ndfBinCoords(sx, sy, res, inv_bin, &i, &j) ? j * res + i : -1;
}

// The footprint blend itself is the container library's (one implementation for the runtime and
// the baker's convergence probe): format::NdfPyramidBlend, initialised from the level records.
using PyramidBlender = format::NdfPyramidBlend;

}  // namespace glintbake::runtime
