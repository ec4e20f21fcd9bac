// SPDX-License-Identifier: Apache-2.0
// Spherical Gaussian (SG) environment lights and their prefiltered shading with a P-NDF
// (Deng et al. 2022, environment prefiltering; Wang et al. 2009 for SG lighting).
//
// An SG light is G(v) = a exp(lambda (mu . v - 1)) of unit axis mu, sharpness lambda > 0 (1/sr
// scale: the lobe's angular std is about 1/sqrt(lambda) radians) and amplitude a (radiance, per
// RGB channel). Directions are unit vectors in the frame the caller shades in (the tangent frame
// of brdf.h: x right, y up, z out).
//
// Prefiltering. Where G >= eps is a cone around mu with
//   cos(theta_max) = 1 + ln(eps / a) / lambda            (the whole sphere when <= -1),
// and the half vectors h = normalize(wo + wi) of the directions wi in that cone cover a region of
// the s-plane; sgHalfVectorRect bounds it by a rectangle. Averaging the P-NDF over that rectangle
// (NdfSource::average: constant cost for tensor-ndf assets) and pulling the smooth factors out of
// the integral at wi = mu gives
//   L_o(wo) ~= D_avg * F(mu . h_mu) G2(mu, wo) / (4 cos(theta_o)) * integral(G),
//   integral(G) = 2 pi a (1 - exp(-2 lambda)) / lambda,
// which is exact for a locally constant D and narrow lobes (the regime of glints under sharp
// lights) and approximate for broad lobes (use BRDF/light sampling there).
//
// Every function is pure, never allocates and never throws; prefilteredSgShading costs one
// NdfSource::average plus ~64 half-vector evaluations.
#pragma once

#include <glintbake/runtime/brdf.h>
#include <glintbake/runtime/runtime.h>

namespace glintbake::runtime {

struct SphericalGaussian {
  Vec3 axis{0.0, 0.0, 1.0};      // mu, unit length
  double sharpness = 1.0;        // lambda > 0
  Rgb amplitude{1.0, 1.0, 1.0};  // a per channel, >= 0
};

// G(v) per channel.
Rgb evalSg(const SphericalGaussian& sg, const Vec3& v);

// Integral of G over the sphere per channel: 2 pi a (1 - exp(-2 lambda)) / lambda (evaluated with
// expm1, accurate for every lambda > 0).
Rgb sgIntegral(const SphericalGaussian& sg);

// The support cone where the largest channel of G is >= eps (eps > 0).
struct SgSupport {
  double cos_theta_max = 1.0;  // in [-1, 1]; -1 = the whole sphere
  bool empty = false;          // eps exceeds the amplitude: nothing is >= eps
};
SgSupport sgSupport(const SphericalGaussian& sg, double eps);

// A rectangle of the s-plane (clamped to [-1, 1]^2) that contains s = (h.x, h.y) of every half
// vector h = normalize(wo + wi) with wi in the support cone (wo unit, any hemisphere). The image of
// the cap's boundary circle is traced at 64 points and the bounding box padded by the largest
// distance between neighbouring traced points (which bounds the chord deviation); the box becomes
// [-1, 1]^2 when the cone contains -wo (h unbounded) or reaches the extreme s = (+-1, 0), (0, +-1).
// kInvalidArgument for non-finite input, eps <= 0 or lambda <= 0. *rect untouched then, and also
// when the support is empty (returns kOk with *has_support = false).
RuntimeStatus sgHalfVectorRect(const SphericalGaussian& sg, double eps, const Vec3& wo, SRect* rect, bool* has_support);

// Average of the BRDF's D over the half-vector rectangle of the SG's support: NdfSource::average
// for P-NDF BRDFs, and for the smooth BRDF the mean of the analytic D at 8 x 8 rectangle points.
RuntimeStatus sgAveragedNdf(const MicrofacetBrdf& brdf, const SphericalGaussian& sg, double eps, const Vec3& wo,
                            double* value);

// Prefiltered outgoing radiance towards wo of the SG light reflected by the BRDF (formula above),
// per channel. 0 when wo or mu is at or below the horizon, or the support is empty.
// eps: the support threshold in radiance units (e.g. 1e-3 of the amplitude).
RuntimeStatus prefilteredSgShading(const MicrofacetBrdf& brdf, const SphericalGaussian& sg, double eps, const Vec3& wo,
                                   Rgb* radiance);

// Importance sampling of the direction distribution G(v) / integral(G) (for a scalar lobe:
// the channels share the shape): cos(theta) = 1 + ln(1 - u1 (1 - exp(-2 lambda))) / lambda.
// Returns the unit direction and writes its solid-angle density to *pdf.
Vec3 sampleSg(const SphericalGaussian& sg, double u1, double u2, double* pdf);
// Solid-angle density of sampleSg at v: lambda exp(lambda (mu . v - 1)) / (2 pi (1 - exp(-2 lambda))).
double sgPdf(const SphericalGaussian& sg, const Vec3& v);

}  // namespace glintbake::runtime
