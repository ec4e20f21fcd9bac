// SPDX-License-Identifier: Apache-2.0
// Kernel timing of the CP sweep, for benchmarks: how close a full ALS sweep comes to the cost of
// its two large contractions (W = C^T X and X (B kr A)), the GEMM-bound floor of a sweep.
#pragma once

#include <glintbake/bake/tensor/cp_decomposition.h>

namespace glintbake::bake::tensor {

struct CpSweepTiming {
  double sweep_seconds = 0.0;        // one full ALS sweep (both contractions, solves, error)
  double contraction_seconds = 0.0;  // the two GEMMs alone, same shapes
};

// Runs `sweeps` (>= 1) plain ALS sweeps at `rank` from a seeded start, then as many repetitions of
// the two contractions alone, on the calling thread; returns the per-sweep medians. The tensor must
// be valid (decomposeCp's rules); otherwise both times are 0.
CpSweepTiming timeCpSweeps(const GroupTensor& tensor, int rank, int sweeps);

}  // namespace glintbake::bake::tensor
