// SPDX-License-Identifier: Apache-2.0
// Sweep and contraction timing for the CP benchmark.
#include <glintbake/bake/tensor/cp_profile.h>

#include "cp_engine.h"
#include "cp_init.h"

#include <algorithm>
#include <chrono>
#include <vector>

namespace glintbake::bake::tensor {

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

CpSweepTiming timeCpSweeps(const GroupTensor& tensor, int rank, int sweeps) {
  CpSweepTiming timing;
  const size_t expected =
      static_cast<size_t>(tensor.bins) * tensor.bins * static_cast<size_t>(std::max(tensor.blocks, 0));
  if (sweeps < 1 || rank < 1 || rank > kMaxCpRank || tensor.bins < 1 || tensor.bins > kMaxBlockBins ||
      tensor.blocks < 1 || tensor.values.size() != expected) {
    return timing;
  }
  using Clock = std::chrono::steady_clock;
  const int bins = tensor.bins, blocks = tensor.blocks;
  CpEngine engine(tensor.values.data(), bins, blocks, rank);
  CpState s;
  randomStart(bins, blocks, rank, 1, s);
  std::vector<double> sweep_times, gemm_times;
  volatile float sink = 0.0f;
  for (int n = 0; n < sweeps; ++n) {
    const auto t0 = Clock::now();
    engine.alsSweep(s, 1e-7);
    sweep_times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  Eigen::Map<const MatF> xt(tensor.values.data(), static_cast<Eigen::Index>(bins) * bins, blocks);
  MatF w(xt.rows(), rank), kr = MatF::Random(xt.rows(), rank), mc(blocks, rank);
  for (int n = 0; n < sweeps; ++n) {
    const auto t0 = Clock::now();
    w.noalias() = xt * s.c;
    mc.noalias() = xt.transpose() * kr;
    gemm_times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    sink = sink + mc(0, 0) + w(0, 0);  // keep both products observable
  }
  timing.sweep_seconds = median(sweep_times);
  timing.contraction_seconds = median(gemm_times);
  return timing;
}

}  // namespace glintbake::bake::tensor
