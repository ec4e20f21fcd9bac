// SPDX-License-Identifier: Apache-2.0
// Two microfacet layers, f = f_base (1 - F_coat) + f_coat (see layered_brdf.h).
#include <glintbake/runtime/layered_brdf.h>

#include "../query_args.h"

#include <algorithm>
#include <cmath>

namespace glintbake::runtime {
namespace {

double mean(const Rgb& c) { return (c.r + c.g + c.b) / 3.0; }

}  // namespace

double LayeredBrdf::coatProbability(const Vec3& wo) const {
  return std::clamp(mean(evalFresnel(fresnel_, std::max(0.0, wo.z))), 0.05, 0.95);
}

RuntimeStatus LayeredBrdf::eval(const Vec3& wi, const Vec3& wo, Rgb* f) const {
  if (!f || !finiteVec3(wi) || !finiteVec3(wo)) return RuntimeStatus::kInvalidArgument;
  Rgb fb, fc;
  if (RuntimeStatus s = base_.eval(wi, wo, &fb); s != RuntimeStatus::kOk) return s;
  if (RuntimeStatus s = coat_.eval(wi, wo, &fc); s != RuntimeStatus::kOk) return s;
  const Vec3 h = normalize(wi + wo);
  const Rgb F = evalFresnel(fresnel_, std::max(0.0, dot(wi, h)));
  *f = {fb.r * (1.0 - F.r) + fc.r, fb.g * (1.0 - F.g) + fc.g, fb.b * (1.0 - F.b) + fc.b};
  return RuntimeStatus::kOk;
}

RuntimeStatus LayeredBrdf::pdf(const Vec3& wi, const Vec3& wo, double* value) const {
  if (!value || !finiteVec3(wi) || !finiteVec3(wo)) return RuntimeStatus::kInvalidArgument;
  double pb = 0.0, pc = 0.0;
  if (RuntimeStatus s = base_.pdf(wi, wo, &pb); s != RuntimeStatus::kOk) return s;
  if (RuntimeStatus s = coat_.pdf(wi, wo, &pc); s != RuntimeStatus::kOk) return s;
  const double q = coatProbability(wo);
  *value = q * pc + (1.0 - q) * pb;
  return RuntimeStatus::kOk;
}

RuntimeStatus LayeredBrdf::sample(const Vec3& wo, double u1, double u2, BrdfSample* out) const {
  if (!out || !finiteVec3(wo) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  const double q = coatProbability(wo);
  // The first uniform chooses the layer and is rescaled for that layer's sampler.
  const bool coat = u1 < q;
  const double v1 = std::min(coat ? u1 / q : (u1 - q) / (1.0 - q), 0.99999999999999989);
  BrdfSample s;
  if (RuntimeStatus st = (coat ? coat_ : base_).sample(wo, v1, u2, &s); st != RuntimeStatus::kOk) return st;
  *out = BrdfSample{};
  out->wi = s.wi;
  if (!(s.pdf > 0.0)) return RuntimeStatus::kOk;
  double p = 0.0;
  if (RuntimeStatus st = pdf(s.wi, wo, &p); st != RuntimeStatus::kOk) return st;
  out->pdf = p;
  if (!(p > 0.0) || !(s.wi.z > 0.0)) return RuntimeStatus::kOk;
  Rgb f;
  if (RuntimeStatus st = eval(s.wi, wo, &f); st != RuntimeStatus::kOk) return st;
  const double w = s.wi.z / p;
  out->weight = {f.r * w, f.g * w, f.b * w};
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
