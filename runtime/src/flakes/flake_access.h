// SPDX-License-Identifier: Apache-2.0
// What the clustered lobes (lobe_ndf.cpp) use of the exact flakes (internal to the runtime).
#pragma once

#include <glintbake/runtime/flake_ndf.h>

namespace glintbake::runtime {

struct FlakeNdfAccess {
  // FlakeNdf::eval with the flakes' footprint weights truncated at window_sigmas standard
  // deviations (a disk: spatial exponent below window_sigmas^2 / 2) instead of 6; the same
  // exponent cutoff and kernels.
  static RuntimeStatus windowedEval(const FlakeNdf& f, const Footprint& fp, const SPoint& s, double window_sigmas,
                                    double* value);
};

}  // namespace glintbake::runtime
