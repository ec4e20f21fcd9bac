// SPDX-License-Identifier: Apache-2.0
// Spherical Gaussian lights: evaluation, integral, support, half-vector range and prefiltering.
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/sg.h>

#include "../query_args.h"

#include <cmath>

namespace glintbake::runtime {
namespace {

constexpr int kBoundaryPoints = 64;

double maxChannel(const Rgb& c) { return std::fmax(c.r, std::fmax(c.g, c.b)); }

// An orthonormal basis (t, b) completing the unit vector n (Duff et al. 2017, "Building an
// Orthonormal Basis, Revisited").
void basis(const Vec3& n, Vec3* t, Vec3* b) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double c = n.x * n.y * a;
  *t = Vec3{1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
  *b = Vec3{c, sign + n.y * n.y * a, -n.y};
}

// 1 - exp(-2 lambda), accurate for small lambda.
double oneMinusExp2(double lambda) { return -std::expm1(-2.0 * lambda); }

bool validSg(const SphericalGaussian& sg) {
  return finiteVec3(sg.axis) && std::isfinite(sg.sharpness) && sg.sharpness > 0.0 && std::isfinite(sg.amplitude.r) &&
         std::isfinite(sg.amplitude.g) && std::isfinite(sg.amplitude.b);
}

}  // namespace

Rgb evalSg(const SphericalGaussian& sg, const Vec3& v) {
  const double e = std::exp(sg.sharpness * (dot(sg.axis, v) - 1.0));
  return {sg.amplitude.r * e, sg.amplitude.g * e, sg.amplitude.b * e};
}

Rgb sgIntegral(const SphericalGaussian& sg) {
  const double k = 2.0 * kPi * oneMinusExp2(sg.sharpness) / sg.sharpness;
  return {sg.amplitude.r * k, sg.amplitude.g * k, sg.amplitude.b * k};
}

SgSupport sgSupport(const SphericalGaussian& sg, double eps) {
  SgSupport support;
  const double a = maxChannel(sg.amplitude);
  if (!(a > 0.0) || !(eps > 0.0) || eps > a) {
    support.empty = true;
    return support;
  }
  const double c = 1.0 + std::log(eps / a) / sg.sharpness;
  support.cos_theta_max = c <= -1.0 ? -1.0 : std::fmin(1.0, c);
  return support;
}

RuntimeStatus sgHalfVectorRect(const SphericalGaussian& sg, double eps, const Vec3& wo, SRect* rect,
                               bool* has_support) {
  if (!validSg(sg) || !finiteVec3(wo) || !std::isfinite(eps) || !(eps > 0.0)) return RuntimeStatus::kInvalidArgument;
  const SgSupport support = sgSupport(sg, eps);
  if (support.empty) {
    *has_support = false;
    return RuntimeStatus::kOk;
  }
  *has_support = true;
  const SRect whole{-1.0, -1.0, 1.0, 1.0};
  const double cos_max = support.cos_theta_max;
  // The cone holds -wo: wi = -wo has no half vector and nearby wi reach every direction.
  if (cos_max <= -1.0 || -dot(wo, sg.axis) >= cos_max) {
    *rect = whole;
    return RuntimeStatus::kOk;
  }
  const double sin_max = std::sqrt(std::fmax(0.0, 1.0 - cos_max * cos_max));
  Vec3 t, b;
  basis(sg.axis, &t, &b);
  double x0 = 2.0, x1 = -2.0, y0 = 2.0, y1 = -2.0;
  double gap = 0.0;
  double prev_x = 0.0, prev_y = 0.0;
  for (int i = 0; i <= kBoundaryPoints; ++i) {
    const double phi = 2.0 * kPi * double(i % kBoundaryPoints) / kBoundaryPoints;
    const Vec3 wi = cos_max * sg.axis + sin_max * (std::cos(phi) * t + std::sin(phi) * b);
    const Vec3 h = normalize(wi + wo);
    x0 = std::fmin(x0, h.x);
    x1 = std::fmax(x1, h.x);
    y0 = std::fmin(y0, h.y);
    y1 = std::fmax(y1, h.y);
    if (i > 0) gap = std::fmax(gap, std::hypot(h.x - prev_x, h.y - prev_y));
    prev_x = h.x;
    prev_y = h.y;
  }
  // Interior extremes of s_x, s_y on the sphere sit at h = (+-1, 0, 0), (0, +-1, 0): include them
  // when they are half vectors of a direction in the cone.
  const Vec3 extremes[4] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  for (const Vec3& h : extremes) {
    const double wo_h = dot(wo, h);
    if (!(wo_h > 0.0)) continue;
    const Vec3 wi = 2.0 * wo_h * h - wo;
    if (dot(wi, sg.axis) >= cos_max) {
      x0 = std::fmin(x0, h.x);
      x1 = std::fmax(x1, h.x);
      y0 = std::fmin(y0, h.y);
      y1 = std::fmax(y1, h.y);
    }
  }
  rect->x0 = std::fmax(-1.0, x0 - gap);
  rect->x1 = std::fmin(1.0, x1 + gap);
  rect->y0 = std::fmax(-1.0, y0 - gap);
  rect->y1 = std::fmin(1.0, y1 + gap);
  // A degenerate box (a cap of zero size) still needs positive area for the average.
  constexpr double kMinSide = 1e-9;
  if (rect->x1 - rect->x0 < kMinSide) rect->x1 = rect->x0 + kMinSide;
  if (rect->y1 - rect->y0 < kMinSide) rect->y1 = rect->y0 + kMinSide;
  return RuntimeStatus::kOk;
}

RuntimeStatus sgAveragedNdf(const MicrofacetBrdf& brdf, const SphericalGaussian& sg, double eps, const Vec3& wo,
                            double* value) {
  SRect rect;
  bool has_support = false;
  const RuntimeStatus st = sgHalfVectorRect(sg, eps, wo, &rect, &has_support);
  if (st != RuntimeStatus::kOk) return st;
  if (!has_support) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  if (brdf.ndfKind() == NdfKind::kSource) {
    if (brdf.source() == nullptr) return RuntimeStatus::kInvalidArgument;
    return brdf.source()->average(brdf.footprint(), rect, value);
  }
  constexpr int kGrid = 8;
  double sum = 0.0;
  for (int j = 0; j < kGrid; ++j) {
    for (int i = 0; i < kGrid; ++i) {
      const double sx = rect.x0 + (i + 0.5) * (rect.x1 - rect.x0) / kGrid;
      const double sy = rect.y0 + (j + 0.5) * (rect.y1 - rect.y0) / kGrid;
      const double r2 = sx * sx + sy * sy;
      if (r2 >= 1.0) continue;
      sum += microfacetD(brdf.shadowingModel(), brdf.alpha(), Vec3{sx, sy, std::sqrt(1.0 - r2)});
    }
  }
  *value = sum / (kGrid * kGrid);
  return RuntimeStatus::kOk;
}

RuntimeStatus prefilteredSgShading(const MicrofacetBrdf& brdf, const SphericalGaussian& sg, double eps, const Vec3& wo,
                                   Rgb* radiance) {
  if (!validSg(sg) || !finiteVec3(wo) || !std::isfinite(eps) || !(eps > 0.0)) return RuntimeStatus::kInvalidArgument;
  if (!(wo.z > 0.0) || !(sg.axis.z > 0.0)) {
    *radiance = Rgb{};
    return RuntimeStatus::kOk;
  }
  double d_avg = 0.0;
  const RuntimeStatus st = sgAveragedNdf(brdf, sg, eps, wo, &d_avg);
  if (st != RuntimeStatus::kOk) return st;
  const Vec3 h = normalize(sg.axis + wo);
  const Rgb f = evalFresnel(brdf.fresnel(), dot(sg.axis, h));
  const double g = smithG2(brdf.shadowingModel(), brdf.alpha(), sg.axis, wo);
  const Rgb integral = sgIntegral(sg);
  const double k = d_avg * g / (4.0 * wo.z);
  *radiance = Rgb{f.r * k * integral.r, f.g * k * integral.g, f.b * k * integral.b};
  return RuntimeStatus::kOk;
}

Vec3 sampleSg(const SphericalGaussian& sg, double u1, double u2, double* pdf) {
  const double lambda = sg.sharpness;
  double cos_theta = 1.0 + std::log1p(-u1 * oneMinusExp2(lambda)) / lambda;
  cos_theta = std::fmin(1.0, std::fmax(-1.0, cos_theta));
  const double sin_theta = std::sqrt(std::fmax(0.0, 1.0 - cos_theta * cos_theta));
  const double phi = 2.0 * kPi * u2;
  Vec3 t, b;
  basis(sg.axis, &t, &b);
  const Vec3 v = normalize(cos_theta * sg.axis + sin_theta * (std::cos(phi) * t + std::sin(phi) * b));
  *pdf = sgPdf(sg, v);
  return v;
}

double sgPdf(const SphericalGaussian& sg, const Vec3& v) {
  const double lambda = sg.sharpness;
  return lambda * std::exp(lambda * (dot(sg.axis, v) - 1.0)) / (2.0 * kPi * oneMinusExp2(lambda));
}

}  // namespace glintbake::runtime
