// SPDX-License-Identifier: Apache-2.0
// Importance sampling of the reference P-NDF as a mixture of the footprint's lobes (sampling.h).
#include <glintbake/reference/sampling.h>

#include "pcg32.h"

#include <glintbake/bake/result.h>

#include <algorithm>
#include <cmath>

namespace glintbake::reference {

namespace {
// Stream selector of the PCG32 generator ("glintref" in ASCII): sequences differ from other
// samplers seeded with the same value.
constexpr uint64_t kStream = 0x676c696e74726566ull;
}  // namespace

struct PndfSampler::State {
  std::vector<FlakeLobe> lobes;
  std::vector<double> cumulative;  // running sums of the weights, in the fixed lobe order
  double total = 0.0;
  detail::Pcg32 rng;
  explicit State(uint64_t seed) : rng(seed, kStream) {}
};

PndfSampler::PndfSampler(const FlakeSet& set, const Footprint& fp, double sigma_r, uint64_t seed)
    : state_(std::make_unique<State>(seed)) {
  GLINTBAKE_CHECK(fp.sigma > 0.0 && sigma_r > 0.0);
  state_->lobes = footprintLobes(set, fp, sigma_r);
  state_->cumulative.resize(state_->lobes.size());
  double total = 0.0;
  for (size_t k = 0; k < state_->lobes.size(); ++k) {
    total += state_->lobes[k].weight;
    state_->cumulative[k] = total;
  }
  state_->total = total;
}

PndfSampler::PndfSampler(PndfSampler&&) noexcept = default;
PndfSampler& PndfSampler::operator=(PndfSampler&&) noexcept = default;
PndfSampler::~PndfSampler() = default;

bool PndfSampler::valid() const { return state_->total > 0.0; }
size_t PndfSampler::lobeCount() const { return state_->lobes.size(); }
double PndfSampler::totalWeight() const { return state_->total; }

PndfSample PndfSampler::next() {
  GLINTBAKE_DCHECK(valid());
  State& st = *state_;
  // Lobe k with probability weight_k / total: the first running sum above u * total.
  const double target = st.rng.uniform() * st.total;
  size_t k = size_t(std::upper_bound(st.cumulative.begin(), st.cumulative.end(), target) - st.cumulative.begin());
  k = std::min(k, st.lobes.size() - 1);
  // Zero-weight lobes (underflowed, far from the centre) are never chosen.
  while (st.lobes[k].weight <= 0.0 && k + 1 < st.lobes.size()) ++k;
  const FlakeLobe& lobe = st.lobes[k];

  // s = mu + L z with C = L L^T (Cholesky factor of the 2x2 covariance).
  const double l00 = std::sqrt(lobe.cov[0]);
  const double l10 = lobe.cov[1] / l00;
  const double l11 = std::sqrt(std::max(0.0, lobe.cov[2] - l10 * l10));
  double z0, z1;
  st.rng.normalPair(&z0, &z1);
  return {lobe.mean[0] + l00 * z0, lobe.mean[1] + l10 * z0 + l11 * z1};
}

std::vector<PndfSample> samplePndf(const FlakeSet& set, const Footprint& fp, double sigma_r, size_t count,
                                   uint64_t seed) {
  PndfSampler sampler(set, fp, sigma_r, seed);
  std::vector<PndfSample> samples;
  if (!sampler.valid()) return samples;
  samples.reserve(count);
  for (size_t n = 0; n < count; ++n) samples.push_back(sampler.next());
  return samples;
}

}  // namespace glintbake::reference
