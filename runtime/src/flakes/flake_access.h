// SPDX-License-Identifier: Apache-2.0
// What the clustered lobes (lobe_ndf.cpp) use of the exact flakes (internal to the runtime).
#pragma once

#include <glintbake/runtime/flake_ndf.h>

#include "gaussian_rect.h"

namespace glintbake::runtime {

struct FlakeNdfAccess {
  // FlakeNdf::eval with the flakes' footprint weights truncated at window_sigmas standard
  // deviations (a disk: spatial exponent below window_sigmas^2 / 2) instead of 6; the same
  // exponent cutoff and kernels.
  static RuntimeStatus windowedEval(const FlakeNdf& f, const Footprint& fp, const SPoint& s, double window_sigmas,
                                    double* value);
  // The sum of the footprint weights of the flakes in that disk (the integral of windowedEval).
  static RuntimeStatus windowedMass(const FlakeNdf& f, const Footprint& fp, double window_sigmas, double* value);
  // A flake of that disk in proportion to its weight (u1 picks its row, u2 the flake in the row;
  // mass from windowedMass) and its lobe; v1, v2 are u1, u2 rescaled within the picked intervals.
  static RuntimeStatus windowedPick(const FlakeNdf& f, const Footprint& fp, double window_sigmas, double u1, double u2,
                                    double mass, flakes::Lobe* lobe, double* v1, double* v2);
};

}  // namespace glintbake::runtime
