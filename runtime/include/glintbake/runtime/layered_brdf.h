// SPDX-License-Identifier: Apache-2.0
// A layered material of two microfacet BRDFs (brdf.h), each with its own NDF.
#pragma once

#include <glintbake/runtime/brdf.h>

namespace glintbake::runtime {

// A coated material of two microfacet layers, each with its own D (its own NDF asset or analytic
// distribution): f = f_base (1 - F_coat) + f_coat (the layering of Xing et al.'s tiny-example
// materials), with F_coat the coat's Fresnel at the half vector of (wi, wo), cos = wi . h. The
// coat's own BRDF carries F_coat too (build it with the same Fresnel). No refraction into the
// base and no absorption in the coat: the light the coat does not reflect reaches the base.
// Sampling picks the coat with probability clamp(F_coat(wo . n), 0.05, 0.95), samples that layer
// and returns the mixture's pdf, so pdf() equals the sample's pdf. Borrowed layers must outlive
// the helper. Pure, const, no allocation.
class LayeredBrdf {
 public:
  LayeredBrdf(const MicrofacetBrdf& base, const MicrofacetBrdf& coat, const Fresnel& coat_fresnel)
      : base_(base), coat_(coat), fresnel_(coat_fresnel) {}

  RuntimeStatus eval(const Vec3& wi, const Vec3& wo, Rgb* f) const;
  RuntimeStatus sample(const Vec3& wo, double u1, double u2, BrdfSample* out) const;
  RuntimeStatus pdf(const Vec3& wi, const Vec3& wo, double* value) const;
  // The probability with which sample() uses the coat for this wo.
  double coatProbability(const Vec3& wo) const;

 private:
  MicrofacetBrdf base_, coat_;
  Fresnel fresnel_;
};

}  // namespace glintbake::runtime
