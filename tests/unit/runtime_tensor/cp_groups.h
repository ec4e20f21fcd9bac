// SPDX-License-Identifier: Apache-2.0
// Test fixtures for the runtime CP queries: compressed groups decomposed from NDF-like tensors,
// with their prefix sums and runtime views.
#pragma once

#include <glintbake/bake/tensor/cp_decomposition.h>
#include <glintbake/bake/tensor/prefix_sums.h>
#include <glintbake/runtime/cp_block.h>

#include <glintbake/bake/tensor/synthetic_groups.h>

#include <memory>
#include <random>

namespace glintbake::runtime::testing {

struct OwnedGroup {
  bake::tensor::CpFactors factors;
  std::vector<float> a_prefix, b_prefix;
  CpGroupView view;
};

inline std::unique_ptr<OwnedGroup> makeGroup(uint64_t seed, bool nonneg, int rank = 16, int blocks = 64) {
  const bake::tensor::GroupTensor t = bake::tensor::makeNdfLikeGroup(32, blocks, seed);
  bake::tensor::CpOptions o;
  o.rank = rank;
  o.nonneg = nonneg;
  o.max_iters = 100;
  auto g = std::make_unique<OwnedGroup>();
  g->factors = bake::tensor::decomposeCp(t, o).value();
  const auto& f = g->factors;
  g->a_prefix = bake::tensor::buildPrefixSums(f.a, f.bins, f.rank);
  g->b_prefix = bake::tensor::buildPrefixSums(f.b, f.bins, f.rank);
  g->view =
      CpGroupView{f.bins, f.rank, f.blocks, f.a.data(), f.b.data(), f.c.data(), g->a_prefix.data(), g->b_prefix.data()};
  return g;
}

// An 8-way trilinear-like blend over two groups (4 blocks each, weights summing to 1).
inline CpMix makeBlend(const OwnedGroup& g0, const OwnedGroup& g1, int first_block = 3) {
  const float w[8] = {0.21f, 0.14f, 0.09f, 0.06f, 0.2f, 0.13f, 0.1f, 0.07f};
  CpBlendTerm terms[8];
  for (int t = 0; t < 8; ++t) {
    const OwnedGroup& g = t < 4 ? g0 : g1;
    terms[t] = CpBlendTerm{&g.view, (first_block + 5 * t) % g.view.blocks, w[t]};
  }
  CpMix mix;
  if (mix.init(terms, 8) != RuntimeStatus::kOk) return CpMix{};
  return mix;
}

class Uniforms {
 public:
  explicit Uniforms(uint64_t seed) : rng_(seed) {}
  double next() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }  // [0, 1)

 private:
  std::mt19937_64 rng_;
};

}  // namespace glintbake::runtime::testing
