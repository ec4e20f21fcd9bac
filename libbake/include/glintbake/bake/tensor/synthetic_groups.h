// SPDX-License-Identifier: Apache-2.0
// Procedural group tensors for tests and benchmarks of the CP compression: NDF-like blocks
// (sparse, peaky, non-negative) and exact low-rank tensors. Seeded and portable: the same seed
// gives the same floats on every platform with IEEE arithmetic and a correctly rounded exp.
#pragma once

#include <glintbake/bake/tensor/cp_decomposition.h>

#include <cstdint>

namespace glintbake::bake::tensor {

// K blocks of B x B bins, each a sum of `lobes_per_block` sharp Gaussian lobes (std 0.6-2.5 bins,
// like glint peaks of an NDF image at 32-bin blocks) with amplitudes in [0.2, 1.2), whose centres
// come from a pool of `pool` positions shared by the group through a window that drifts with k
// (neighbouring footprints see overlapping flake sets), plus a faint broad lobe.
// bins in [1, kMaxBlockBins], blocks >= 1, pool >= 2, lobes_per_block >= 0.
GroupTensor makeNdfLikeGroup(int bins, int blocks, uint64_t seed, int pool = 48, int lobes_per_block = 10);

// An exact rank-`rank` tensor whose factors are uniform in [0, 1) (positive, hence strongly
// correlated columns: a slow case for ALS).
GroupTensor makeLowRankGroup(int bins, int blocks, int rank, uint64_t seed);

}  // namespace glintbake::bake::tensor
