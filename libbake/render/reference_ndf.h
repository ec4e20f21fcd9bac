// SPDX-License-Identifier: Apache-2.0
// The reference P-NDF of one footprint behind the runtime's NdfSource interface, so that the
// renderer's BRDF code is the same for every --ndf mode. The lobes (glintbake::reference,
// footprintLobes) are gathered at construction; every query ignores its footprint argument and
// answers for the footprint given to the constructor.
//  - eval: the exact sum of the lobe densities (not zeroed outside the unit disk);
//  - sample: a lobe chosen by weight, then s ~ N(mu_k, C_k): the density is eval / total weight,
//    which pdf() returns;
//  - average: the exact rectangle integral of every lobe over the rectangle's area;
//  - mass: the total lobe weight; image: not offered (kInvalidArgument).
// Not shared between threads; gather() re-aims one at another footprint, reusing its storage (a
// renderer keeps one per tile). Const queries do not allocate.
#pragma once

#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/ndf_source.h>

#include <limits>
#include <vector>

namespace glintbake::bake::render {

class ReferencePndf final : public runtime::NdfSource {
 public:
  ReferencePndf() = default;
  ReferencePndf(const reference::FlakeSet& flakes, const runtime::Footprint& footprint, double sigma_r);
  // Gathers the lobes of another footprint (replacing the current ones).
  void gather(const reference::FlakeSet& flakes, const runtime::Footprint& footprint, double sigma_r);

  // Not a container asset: kind kUnknown; every footprint is answered exactly.
  format::AssetKind kind() const override { return format::AssetKind::kUnknown; }
  int resolution() const override { return 0; }
  runtime::FootprintRange footprintRange() const override;
  runtime::MapSize mapSize() const override { return map_size_; }
  runtime::MapWrap wrap() const override { return wrap_; }
  runtime::RuntimeStatus eval(const runtime::Footprint&, const runtime::SPoint& s, double* value) const override;
  runtime::RuntimeStatus average(const runtime::Footprint&, const runtime::SRect& rect, double* value) const override;
  runtime::RuntimeStatus sample(const runtime::Footprint&, double u1, double u2,
                                runtime::NdfSample* out) const override;
  runtime::RuntimeStatus pdf(const runtime::Footprint&, const runtime::SPoint& s, double* value) const override;
  runtime::RuntimeStatus mass(const runtime::Footprint&, double* value) const override;
  runtime::RuntimeStatus image(const runtime::Footprint&, float*, size_t) const override {
    return runtime::RuntimeStatus::kInvalidArgument;
  }

 private:
  std::vector<reference::FlakeLobe> lobes_;  // the footprint's lobes of positive weight
  std::vector<double> cdf_;                  // running weight sums
  double total_ = 0.0;
  runtime::MapSize map_size_;
  runtime::MapWrap wrap_ = runtime::MapWrap::kRepeat;
  double evalSum(double sx, double sy) const;
};

}  // namespace glintbake::bake::render
