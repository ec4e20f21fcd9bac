// SPDX-License-Identifier: Apache-2.0
// Analytic microfacet distributions, Smith shadowing, Fresnel and the P-NDF microfacet BRDF.
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/brdf.h>

#include "../query_args.h"

#include <cmath>
#include <complex>

namespace glintbake::runtime {
namespace {

// tan^2(theta) of a unit direction, from its z component.
double tan2Theta(const Vec3& w) {
  const double cos2 = w.z * w.z;
  const double sin2 = std::fmax(0.0, 1.0 - cos2);
  return sin2 / cos2;
}

double clampAlpha(double alpha) { return std::fmin(4.0, std::fmax(kMinAlpha, alpha)); }

}  // namespace

Vec3 normalize(const Vec3& v) {
  const double len = std::sqrt(dot(v, v));
  if (!(len > 0.0)) return v;
  return (1.0 / len) * v;
}

double microfacetD(MicrofacetModel model, double alpha, const Vec3& h) {
  if (!(h.z > 0.0)) return 0.0;
  alpha = clampAlpha(alpha);
  const double a2 = alpha * alpha;
  const double cos2 = h.z * h.z;
  const double cos4 = cos2 * cos2;
  const double t2 = tan2Theta(h);
  if (model == MicrofacetModel::kBeckmann) return std::exp(-t2 / a2) / (kPi * a2 * cos4);
  const double e = 1.0 + t2 / a2;
  return 1.0 / (kPi * a2 * cos4 * e * e);
}

double smithLambda(MicrofacetModel model, double alpha, const Vec3& w) {
  if (!(w.z > 0.0)) return 0.0;
  alpha = clampAlpha(alpha);
  const double t2 = tan2Theta(w);
  if (t2 == 0.0) return 0.0;
  if (model == MicrofacetModel::kGgx) return 0.5 * (-1.0 + std::sqrt(1.0 + alpha * alpha * t2));
  const double a = 1.0 / (alpha * std::sqrt(t2));
  // For large a the bracket cancels to far below double precision: Lambda < 1e-40 there.
  if (a > 12.0) return 0.0;
  return 0.5 * (std::erf(a) - 1.0) + std::exp(-a * a) / (2.0 * a * std::sqrt(kPi));
}

double smithG2(MicrofacetModel model, double alpha, const Vec3& wi, const Vec3& wo) {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return 0.0;
  return 1.0 / (1.0 + smithLambda(model, alpha, wi) + smithLambda(model, alpha, wo));
}

Vec3 sampleMicrofacetNormal(MicrofacetModel model, double alpha, double u1, double u2) {
  alpha = clampAlpha(alpha);
  const double a2 = alpha * alpha;
  const double t2 = model == MicrofacetModel::kBeckmann ? -a2 * std::log1p(-u1) : a2 * u1 / (1.0 - u1);
  const double cos_theta = 1.0 / std::sqrt(1.0 + t2);
  const double sin_theta = std::sqrt(std::fmax(0.0, 1.0 - cos_theta * cos_theta));
  const double phi = 2.0 * kPi * u2;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

double conductorFresnel(double cos_theta, double eta, double k) {
  cos_theta = std::fmin(1.0, std::fmax(0.0, cos_theta));
  const std::complex<double> n(eta, k);
  const double sin2 = 1.0 - cos_theta * cos_theta;
  const std::complex<double> sin2_t = sin2 / (n * n);
  const std::complex<double> cos_t = std::sqrt(1.0 - sin2_t);
  const std::complex<double> r_parl = (n * cos_theta - cos_t) / (n * cos_theta + cos_t);
  const std::complex<double> r_perp = (cos_theta - n * cos_t) / (cos_theta + n * cos_t);
  const double r = 0.5 * (std::norm(r_parl) + std::norm(r_perp));
  return std::fmin(1.0, std::fmax(0.0, r));
}

Rgb evalFresnel(const Fresnel& fresnel, double cos_theta_d) {
  const double c = std::fmin(1.0, std::fmax(0.0, cos_theta_d));
  switch (fresnel.kind) {
    case FresnelKind::kSchlick: {
      const double m = 1.0 - c;
      const double m5 = (m * m) * (m * m) * m;
      return {fresnel.f0.r + (1.0 - fresnel.f0.r) * m5, fresnel.f0.g + (1.0 - fresnel.f0.g) * m5,
              fresnel.f0.b + (1.0 - fresnel.f0.b) * m5};
    }
    case FresnelKind::kConductor:
      return {conductorFresnel(c, fresnel.eta.r, fresnel.k.r), conductorFresnel(c, fresnel.eta.g, fresnel.k.g),
              conductorFresnel(c, fresnel.eta.b, fresnel.k.b)};
    case FresnelKind::kNone:
    default:
      return {1.0, 1.0, 1.0};
  }
}

MicrofacetBrdf MicrofacetBrdf::smooth(MicrofacetModel model, double alpha, const Fresnel& fresnel) {
  MicrofacetBrdf brdf;
  brdf.kind_ = NdfKind::kSmooth;
  brdf.model_ = model;
  brdf.alpha_ = clampAlpha(alpha);
  brdf.fresnel_ = fresnel;
  return brdf;
}

MicrofacetBrdf MicrofacetBrdf::glinty(const NdfSource* source, const Footprint& footprint,
                                      MicrofacetModel shadowing_model, double alpha, const Fresnel& fresnel) {
  MicrofacetBrdf brdf;
  brdf.kind_ = NdfKind::kSource;
  brdf.source_ = source;
  brdf.footprint_ = footprint;
  brdf.model_ = shadowing_model;
  brdf.alpha_ = clampAlpha(alpha);
  brdf.fresnel_ = fresnel;
  return brdf;
}

RuntimeStatus MicrofacetBrdf::ndf(const Vec3& h, double* value) const {
  if (!finiteVec3(h)) return RuntimeStatus::kInvalidArgument;
  if (!(h.z > 0.0)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  if (kind_ == NdfKind::kSmooth) {
    *value = microfacetD(model_, alpha_, h);
    return RuntimeStatus::kOk;
  }
  if (source_ == nullptr) return RuntimeStatus::kInvalidArgument;
  return source_->eval(footprint_, SPoint{h.x, h.y}, value);
}

RuntimeStatus MicrofacetBrdf::eval(const Vec3& wi, const Vec3& wo, Rgb* f) const {
  if (!finiteVec3(wi) || !finiteVec3(wo)) return RuntimeStatus::kInvalidArgument;
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) {
    *f = Rgb{};
    return RuntimeStatus::kOk;
  }
  const Vec3 h = normalize(wi + wo);
  double d = 0.0;
  const RuntimeStatus st = ndf(h, &d);
  if (st != RuntimeStatus::kOk) return st;
  const double g = smithG2(model_, alpha_, wi, wo);
  const double scale = d * g / (4.0 * wi.z * wo.z);
  const Rgb fr = evalFresnel(fresnel_, dot(wi, h));
  *f = Rgb{fr.r * scale, fr.g * scale, fr.b * scale};
  return RuntimeStatus::kOk;
}

RuntimeStatus MicrofacetBrdf::sample(const Vec3& wo, double u1, double u2, BrdfSample* out) const {
  if (!finiteVec3(wo) || !std::isfinite(u1) || !std::isfinite(u2)) return RuntimeStatus::kInvalidArgument;
  BrdfSample result;
  if (!(wo.z > 0.0)) {
    *out = result;
    return RuntimeStatus::kOk;
  }
  Vec3 h;
  double density_h = 0.0;  // solid-angle density of h
  if (kind_ == NdfKind::kSmooth) {
    h = sampleMicrofacetNormal(model_, alpha_, u1, u2);
    density_h = microfacetD(model_, alpha_, h) * h.z;
  } else {
    if (source_ == nullptr) return RuntimeStatus::kInvalidArgument;
    NdfSample s;
    const RuntimeStatus st = source_->sample(footprint_, u1, u2, &s);
    if (st != RuntimeStatus::kOk) {
      // A footprint with no mass (e.g. outside a clamped map) reflects nothing.
      *out = result;
      return RuntimeStatus::kOk;
    }
    const double r2 = s.s.x * s.s.x + s.s.y * s.s.y;
    if (!(r2 < 1.0)) {
      *out = result;
      return RuntimeStatus::kOk;
    }
    h = Vec3{s.s.x, s.s.y, std::sqrt(1.0 - r2)};
    density_h = s.pdf * h.z;
  }
  const double wo_h = dot(wo, h);
  if (!(wo_h > 0.0) || !(density_h > 0.0)) {
    *out = result;
    return RuntimeStatus::kOk;
  }
  result.wi = normalize(2.0 * wo_h * h - wo);
  // Report the density exactly as pdf() computes it from (wi, wo), so both agree up to rounding.
  const RuntimeStatus st = pdf(result.wi, wo, &result.pdf);
  if (st != RuntimeStatus::kOk) return st;
  if (result.wi.z > 0.0 && result.pdf > 0.0) {
    Rgb f;
    const RuntimeStatus se = eval(result.wi, wo, &f);
    if (se != RuntimeStatus::kOk) return se;
    const double w = result.wi.z / result.pdf;
    result.weight = Rgb{f.r * w, f.g * w, f.b * w};
  }
  *out = result;
  return RuntimeStatus::kOk;
}

RuntimeStatus MicrofacetBrdf::pdf(const Vec3& wi, const Vec3& wo, double* value) const {
  if (!finiteVec3(wi) || !finiteVec3(wo)) return RuntimeStatus::kInvalidArgument;
  const Vec3 sum = wi + wo;
  if (!(wo.z > 0.0) || !(dot(sum, sum) > 0.0)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  const Vec3 h = normalize(sum);
  const double wo_h = dot(wo, h);
  if (!(h.z > 0.0) || !(wo_h > 0.0)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  double d = 0.0;
  if (kind_ == NdfKind::kSmooth) {
    d = microfacetD(model_, alpha_, h);
  } else {
    if (source_ == nullptr) return RuntimeStatus::kInvalidArgument;
    const RuntimeStatus st = source_->pdf(footprint_, SPoint{h.x, h.y}, &d);
    if (st != RuntimeStatus::kOk) return st;
  }
  *value = d * h.z / (4.0 * wo_h);
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
