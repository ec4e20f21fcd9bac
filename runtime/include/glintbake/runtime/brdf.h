// SPDX-License-Identifier: Apache-2.0
// A microfacet reflection BRDF whose normal distribution D is the P-NDF of a pixel footprint (any
// NdfSource: ndf-pyramid, tensor-ndf, ...), or, for the look without glints, an analytic GGX or
// Beckmann distribution (Walter et al. 2007, "Microfacet Models for Refraction through Rough
// Surfaces"; Heitz 2014, "Understanding the Masking-Shadowing Function").
//
// Frames and units. Directions are unit vectors in the tangent frame of the shading point:
// x = right (texture u), y = up (texture v, green up), z = the macro normal (formats/SPEC.md).
// Both wi (towards the light) and wo (towards the viewer) point away from the surface.
//
// From the s-plane to solid angle. The NDF assets store a density D_s(s) per unit s-plane area,
// where s = (h_x, h_y) is the projection of the microfacet normal h. Since ds = cos(theta_h) dw_h,
//   - the microfacet distribution with the usual normalisation (integral of D(h) cos(theta_h) dw_h
//     over the hemisphere = 1) is D(h) = D_s(h_x, h_y): the same number;
//   - the solid-angle density of h when s is drawn from D_s is p_h(h) = D_s(s) cos(theta_h);
//   - reflecting wo about h gives wi with density p(wi) = p_h(h) / (4 |wo . h|) (Walter et al. 2007,
//     eq. 14), i.e. p(wi) = D_s(s) cos(theta_h) / (4 |wo . h|).
//
// The BRDF (reciprocal in wi and wo):
//   f(wi, wo) = F(wi . h) D(h) G2(wi, wo) / (4 cos(theta_i) cos(theta_o)),  h = normalize(wi + wo),
// with G2 the height-correlated Smith term 1 / (1 + Lambda(wi) + Lambda(wo)) of a smooth GGX or
// Beckmann surface of the material's base roughness alpha (the shadowing comes from the base
// roughness, not from the map). f = 0 when either direction is at or
// below the horizon.
//
// Thread safety and cost: every function is pure or const, never allocates, never throws; the
// cost is that of one NdfSource query (eval, pdf or sample) plus a few dozen flops.
#pragma once

#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/runtime.h>

#include <cstdint>

namespace glintbake::runtime {

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
};

// Linear RGB triple (reflectances, radiances).
struct Rgb {
  double r = 0.0, g = 0.0, b = 0.0;
};

// The analytic distributions, used for Smith shadowing of every BRDF and as D of the smooth BRDF.
enum class MicrofacetModel : int32_t {
  kGgx = 0,       // Trowbridge-Reitz (Walter et al. 2007, eq. 33)
  kBeckmann = 1,  // Beckmann (Walter et al. 2007, eq. 25)
};

// Smallest accepted roughness alpha (below it GGX and Beckmann are numerically a mirror).
constexpr double kMinAlpha = 1e-4;

// Analytic D(h) with the normalisation integral D(h) cos(theta_h) dw_h = 1, for a unit h (0 when
// h.z <= 0). alpha in [kMinAlpha, 4]. Pure.
double microfacetD(MicrofacetModel model, double alpha, const Vec3& h);

// Smith Lambda(w) of the model, exact for both (Heitz 2014, eqs. 72 and 73: GGX
// (-1 + sqrt(1 + 1/a^2)) / 2, Beckmann (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)), with
// a = 1 / (alpha tan(theta))). 0 at normal incidence; grows without bound towards grazing.
double smithLambda(MicrofacetModel model, double alpha, const Vec3& w);

// Height-correlated masking-shadowing G2(wi, wo) = 1 / (1 + Lambda(wi) + Lambda(wo)) (Heitz 2014,
// eq. 99), in [0, 1]; 0 when either direction is at or below the horizon.
double smithG2(MicrofacetModel model, double alpha, const Vec3& wi, const Vec3& wo);

// Draws h with solid-angle density microfacetD(h) * h.z from two uniforms in [0, 1) (Walter et al.
// 2007, eqs. 28-29 and 35-36). Pure.
Vec3 sampleMicrofacetNormal(MicrofacetModel model, double alpha, double u1, double u2);

// Fresnel reflectance.
enum class FresnelKind : int32_t {
  kNone = 0,       // F = 1 (white furnace tests)
  kSchlick = 1,    // F = f0 + (1 - f0) (1 - cos)^5 (Schlick 1994), f0 per channel
  kConductor = 2,  // exact unpolarised conductor Fresnel with complex IOR eta + i k per channel
};

struct Fresnel {
  FresnelKind kind = FresnelKind::kNone;
  Rgb f0{1.0, 1.0, 1.0};    // kSchlick: reflectance at normal incidence, [0, 1]
  Rgb eta{0.2, 0.92, 1.1};  // kConductor: real part of the IOR (default: gold, approx. RGB)
  Rgb k{3.9, 2.45, 2.14};   // kConductor: imaginary part (extinction), >= 0
};

// Unpolarised reflectance of an interface with complex relative IOR eta + i k at cos_theta in
// [0, 1] (the exact expression, e.g. pbrt-v4 section 9.5.2). Returns a value in [0, 1]. Pure.
double conductorFresnel(double cos_theta, double eta, double k);

// F at the angle with cos(theta_d) = cos_theta_d (= wi . h), clamped to [0, 1]. Pure.
Rgb evalFresnel(const Fresnel& fresnel, double cos_theta_d);

// Which distribution a MicrofacetBrdf uses as D.
enum class NdfKind : int32_t {
  kSmooth = 0,  // the analytic `shadowing_model` distribution of roughness `alpha`
  kSource = 1,  // the P-NDF of `footprint` from `source`
};

// A result of MicrofacetBrdf::sample.
struct BrdfSample {
  Vec3 wi;
  double pdf = 0.0;  // solid-angle density of wi (== pdf(wi, wo) up to the rounding of h)
  Rgb weight;        // f(wi, wo) cos(theta_i) / pdf; zero when wi falls below the horizon
};

// The BRDF of one shading point. A small value type: build one per shading point (the footprint
// changes from pixel to pixel). The NdfSource is borrowed and must outlive the BRDF.
class MicrofacetBrdf {
 public:
  // Analytic D (the renderer's --ndf smooth). alpha in [kMinAlpha, 4].
  static MicrofacetBrdf smooth(MicrofacetModel model, double alpha, const Fresnel& fresnel);
  // D = the P-NDF of `footprint` (texels of the asset's map) from `source`; Smith shadowing from
  // the analytic `shadowing_model` of roughness `alpha`.
  static MicrofacetBrdf glinty(const NdfSource* source, const Footprint& footprint, MicrofacetModel shadowing_model,
                               double alpha, const Fresnel& fresnel);

  NdfKind ndfKind() const { return kind_; }

  // D(h) of a unit microfacet normal h (the s-plane density at (h.x, h.y); 0 for h.z <= 0).
  RuntimeStatus ndf(const Vec3& h, double* value) const;

  // f(wi, wo) per channel, 1/sr. kInvalidArgument for a non-finite direction or from the source.
  RuntimeStatus eval(const Vec3& wi, const Vec3& wo, Rgb* f) const;

  // Samples wi by drawing h from D (NdfSource::sample, or the analytic sampler) and reflecting wo
  // about it. u1, u2 in [0, 1). When h cannot reflect wo (wo . h <= 0) or the source has no mass,
  // returns kOk with pdf = 0 and zero weight (the caller discards the sample).
  RuntimeStatus sample(const Vec3& wo, double u1, double u2, BrdfSample* out) const;

  // Density of sample() producing wi for this wo: D_s(s) cos(theta_h) / (4 |wo . h|) with the
  // source's pdf() as D_s. 0 when wo is at or below the horizon or h = 0.
  RuntimeStatus pdf(const Vec3& wi, const Vec3& wo, double* value) const;

  // Accessors used by the environment prefiltering (sg.h).
  const NdfSource* source() const { return source_; }
  const Footprint& footprint() const { return footprint_; }
  MicrofacetModel shadowingModel() const { return model_; }
  double alpha() const { return alpha_; }
  const Fresnel& fresnel() const { return fresnel_; }

 private:
  NdfKind kind_ = NdfKind::kSmooth;
  const NdfSource* source_ = nullptr;
  Footprint footprint_;
  MicrofacetModel model_ = MicrofacetModel::kGgx;
  double alpha_ = 0.1;
  Fresnel fresnel_;
};

// Small vector helpers (inline, pure).
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Unit vector along v; v itself when |v| = 0.
Vec3 normalize(const Vec3& v);

}  // namespace glintbake::runtime
