// SPDX-License-Identifier: Apache-2.0
// Starting points of the CP decompositions and the mode-3 range finder (private to libbake/tensor).
#pragma once

#include "cp_engine.h"

namespace glintbake::bake::tensor {

// Leading left singular vectors of the mode-1 and mode-2 unfoldings (HOSVD, De Lathauwer et al.
// 2000), from the B x B Gram matrices in double; each vector's largest entry is made positive.
// Ranks above B are filled with seeded Gaussian columns. x: K x (B*B) row-major.
// nonneg: absolute values of the vectors (a non-negative start for HALS).
void hosvdStart(const float* x, int bins, int blocks, int rank, uint64_t seed, bool nonneg, CpState& state);

// Seeded uniform [0, 1) entries in A, B and C (the published random start).
void randomStart(int bins, int blocks, int rank, uint64_t seed, CpState& state);

// Orthonormal K x L basis of the mode-3 fibres' range: a seeded sketch Y = X Omega (Gaussian
// Omega, or with `sparse` a sign sketch with one non-zero per bin, Clarkson & Woodruff 2013)
// followed by `power_iters` power iterations, each re-orthonormalised by QR (Halko, Martinsson &
// Tropp 2011, alg. 4.4).
MatF modeThreeRangeBasis(const float* x, int bins, int blocks, int basis, uint64_t seed, int power_iters, bool sparse);

}  // namespace glintbake::bake::tensor
