// SPDX-License-Identifier: Apache-2.0
// The reference P-NDF of one footprint as an NdfSource.
#include "reference_ndf.h"

#include <glintbake/format/numbers.h>

#include <algorithm>
#include <cmath>

namespace glintbake::bake::render {

using runtime::RuntimeStatus;

ReferencePndf::ReferencePndf(const reference::FlakeSet& flakes, const runtime::Footprint& footprint, double sigma_r) {
  gather(flakes, footprint, sigma_r);
}

void ReferencePndf::gather(const reference::FlakeSet& flakes, const runtime::Footprint& footprint, double sigma_r) {
  map_size_ = runtime::MapSize{flakes.width, flakes.height};
  wrap_ = flakes.wrap == bake::Wrap::kRepeat ? runtime::MapWrap::kRepeat : runtime::MapWrap::kClamp;
  reference::Footprint fp;
  fp.x = footprint.x;
  fp.y = footprint.y;
  fp.sigma = footprint.sigma;
  reference::footprintLobes(flakes, fp, sigma_r, &lobes_);
  lobes_.erase(
      std::remove_if(lobes_.begin(), lobes_.end(), [](const reference::FlakeLobe& l) { return !(l.weight > 0.0); }),
      lobes_.end());
  cdf_.resize(lobes_.size());
  total_ = 0.0;
  for (size_t k = 0; k < lobes_.size(); ++k) {
    total_ += lobes_[k].weight;
    cdf_[k] = total_;
  }
}

double ReferencePndf::evalSum(double sx, double sy) const {
  double sum = 0.0;
  for (const reference::FlakeLobe& l : lobes_) sum += reference::lobeDensity(l, sx, sy);
  return sum;
}

runtime::FootprintRange ReferencePndf::footprintRange() const {
  runtime::FootprintRange range;
  range.exact_max_sigma = std::numeric_limits<double>::infinity();
  return range;
}

RuntimeStatus ReferencePndf::eval(const runtime::Footprint&, const runtime::SPoint& s, double* value) const {
  if (!std::isfinite(s.x) || !std::isfinite(s.y)) return RuntimeStatus::kInvalidArgument;
  *value = evalSum(s.x, s.y);
  return RuntimeStatus::kOk;
}

RuntimeStatus ReferencePndf::average(const runtime::Footprint&, const runtime::SRect& rect, double* value) const {
  if (!(rect.x1 > rect.x0) || !(rect.y1 > rect.y0)) return RuntimeStatus::kInvalidArgument;
  double sum = 0.0;
  for (const reference::FlakeLobe& l : lobes_) {
    sum += l.weight * reference::gaussianRectangleIntegral(l.mean, l.cov, rect.x0, rect.x1, rect.y0, rect.y1);
  }
  *value = sum / ((rect.x1 - rect.x0) * (rect.y1 - rect.y0));
  return RuntimeStatus::kOk;
}

RuntimeStatus ReferencePndf::sample(const runtime::Footprint&, double u1, double u2, runtime::NdfSample* out) const {
  if (lobes_.empty() || !(total_ > 0.0)) return RuntimeStatus::kInvalidArgument;
  // Choose a lobe with u1 and reuse the remainder of u1 inside the lobe's interval.
  const double target = u1 * total_;
  const size_t k =
      std::min(lobes_.size() - 1, size_t(std::upper_bound(cdf_.begin(), cdf_.end(), target) - cdf_.begin()));
  const double lo = k == 0 ? 0.0 : cdf_[k - 1];
  double v1 = (target - lo) / (cdf_[k] - lo);
  v1 = std::min(std::max(v1, 1e-300), 1.0 - 1e-16);
  // Box-Muller: two independent normals from (v1, u2).
  const double r = std::sqrt(-2.0 * std::log1p(-v1));
  const double phi = kTwoPi * u2;
  const double z0 = r * std::cos(phi), z1 = r * std::sin(phi);
  // s = mean + L z with L the lower Cholesky factor of the lobe's covariance.
  const reference::FlakeLobe& l = lobes_[k];
  const double l00 = std::sqrt(l.cov[0]);
  const double l10 = l.cov[1] / l00;
  const double l11 = std::sqrt(std::max(0.0, l.cov[2] - l10 * l10));
  out->s.x = l.mean[0] + l00 * z0;
  out->s.y = l.mean[1] + l10 * z0 + l11 * z1;
  out->pdf = evalSum(out->s.x, out->s.y) / total_;
  return RuntimeStatus::kOk;
}

RuntimeStatus ReferencePndf::pdf(const runtime::Footprint&, const runtime::SPoint& s, double* value) const {
  if (!std::isfinite(s.x) || !std::isfinite(s.y)) return RuntimeStatus::kInvalidArgument;
  *value = total_ > 0.0 ? evalSum(s.x, s.y) / total_ : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus ReferencePndf::mass(const runtime::Footprint&, double* value) const {
  *value = total_;
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::bake::render
