// Importance sampling of the reference P-NDF as a mixture of the footprint's lobes (sampling.h).
#include <glintbake/reference/sampling.h>

#include "pcg32.h"

#include <glintbake/bake/result.h>

#include <algorithm>
#include <cmath>

namespace glintbake::reference {

std::vector<PndfSample> samplePndf(const FlakeSet& set, const Footprint& fp, double sigma_r, size_t count,
                                   uint64_t seed) {
  GLINTBAKE_CHECK(fp.sigma > 0.0 && sigma_r > 0.0);
  const std::vector<FlakeLobe> lobes = footprintLobes(set, fp, sigma_r);

  // Running sums of the weights, in the fixed lobe order.
  std::vector<double> cumulative(lobes.size());
  double total = 0.0;
  for (size_t k = 0; k < lobes.size(); ++k) {
    total += lobes[k].weight;
    cumulative[k] = total;
  }
  std::vector<PndfSample> samples;
  if (!(total > 0.0)) return samples;
  samples.reserve(count);

  detail::Pcg32 rng(seed, 0x6c696e7472656600ull);
  for (size_t n = 0; n < count; ++n) {
    // Lobe k with probability weight_k / total: the first running sum above u * total.
    const double target = rng.uniform() * total;
    size_t k = size_t(std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin());
    k = std::min(k, lobes.size() - 1);
    // Skip zero-weight lobes that share the running sum (underflowed weights far from the centre).
    while (lobes[k].weight <= 0.0 && k + 1 < lobes.size()) ++k;
    const FlakeLobe& lobe = lobes[k];

    // s = mu + L z with C = L L^T (Cholesky of the 2x2 covariance).
    const double l00 = std::sqrt(lobe.cov[0]);
    const double l10 = lobe.cov[1] / l00;
    const double l11 = std::sqrt(std::max(0.0, lobe.cov[2] - l10 * l10));
    double z0, z1;
    rng.normalPair(&z0, &z1);
    samples.push_back({lobe.mean[0] + l00 * z0, lobe.mean[1] + l10 * z0 + l11 * z1});
  }
  return samples;
}

}  // namespace glintbake::reference
