// SPDX-License-Identifier: Apache-2.0
// Runtime-lite LTC area lights: lookup of a linearly transformed cosine from a fitted table and the
// integral of that LTC over a polygonal light (Heitz, Dupuy, Hill and Neubelt 2016).
//
// Shading frame: z = the shading normal N, x = the component of the view vector V orthogonal to N
// (normalised), y = z cross x. ltcShadingFrame() builds it; polygon vertices are given relative to
// the shading point, expressed in that frame. Table parametrisation (formats/SPEC.md, ltc-table):
// cell (a, t) of an N x N table holds roughness a / (N-1) (alpha_GGX = roughness^2) and
// cos(theta_V) = 1 - (t / (N-1))^2.
//
// Thread safety: an LtcTable is immutable after open; lookups and integrals are const, never
// allocate and may run concurrently. Opening is safe on untrusted files (sizes and values checked).
#pragma once

#include <glintbake/runtime/runtime.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glintbake::runtime {

// Largest polygon ltcIntegratePolygon() accepts (clipping to the horizon may add vertices; the
// internal buffer holds twice this many).
constexpr int kLtcMaxPolygonVertices = 16;

// One looked-up LTC: the inverse transform (row-major, normalised by its middle element) and the
// two magnitudes of the published layout.
struct LtcCoefficients {
  float inv_m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  float norm = 0.0f;     // integral of BRDF * cos over the hemisphere (Fresnel = 1)
  float fresnel = 0.0f;  // the same integral weighted by (1 - V.H)^5
  float sphere = 0.0f;   // not interpolated by lookup(); see LtcTable::sphereFactor
};

class LtcTable {
 public:
  LtcTable() = default;

  // Loads an ltc-table container (sections 48/0 and 48/1). Allocates once, here.
  RuntimeStatus open(const char* path);
  RuntimeStatus openMemory(const void* data, size_t size);
  // Adopts arrays in the published layout: size x size x 4 floats each, flat index a + size t.
  RuntimeStatus fromArrays(int size, const float* ltc1, const float* ltc2);

  bool valid() const { return size_ > 0; }
  int size() const { return size_; }

  // Bilinear lookup at roughness in [0, 1] (sqrt of alpha_GGX) and cos(theta_V) in [0, 1]; both
  // are clamped. Returns kInvalidArgument on an empty table or non-finite inputs.
  RuntimeStatus lookup(float roughness, float cos_theta_v, LtcCoefficients* out) const;

  // The horizon-clipping factor of a sphere light (ltc_2.w): bilinear in z (cosine of the average
  // direction's elevation, [-1, 1]) and len (its length, [0, 1]); returns 0 on an empty table.
  float sphereFactor(float z, float len) const;

  // Published-layout arrays (size * size * 4 floats each).
  const float* ltc1() const { return ltc1_.data(); }
  const float* ltc2() const { return ltc2_.data(); }

 private:
  int size_ = 0;
  std::vector<float> ltc1_, ltc2_;
};

// Builds the shading frame from the unit normal n and the unit view vector v (pointing away from
// the surface); x/y/z receive the frame's axes in the caller's space. If v is parallel to n any
// perpendicular x is chosen.
void ltcShadingFrame(const float n[3], const float v[3], float x[3], float y[3], float z[3]);

// Cosine of the view angle for lookup(): clamp(dot(n, v), 0, 1).
float ltcCosTheta(const float n[3], const float v[3]);

// The integral over a polygonal light of the LTC *without* its magnitude: vertices (count in
// [3, kLtcMaxPolygonVertices]) relative to the shading point in the shading frame, wound so that
// the right-hand normal (v1 - v0) x (v2 - v0) points away from the shading point (counter-clockwise
// in the x-y plane for a light above the surface, seen from above). The polygon is transformed by inv_m,
// clipped to the upper hemisphere, projected to the unit sphere and integrated edge by edge
// (Stokes' theorem; Arvo 1995, Heitz et al. 2016 eq. 11). A polygon covering the whole upper
// hemisphere gives 1. Polygons wound the other way give 0 unless two_sided (then |integral|). Returns 0 for
// invalid arguments.
float ltcIntegratePolygon(const LtcCoefficients& ltc, const float (*vertices)[3], int count, bool two_sided);

// The same integral for the clamped cosine (inv_m = identity): the polygon's form factor.
float ltcFormFactor(const float (*vertices)[3], int count, bool two_sided);

// Specular magnitude with Schlick Fresnel of normal-incidence reflectance f0 in [0, 1]:
// f0 * norm + (1 - f0) * fresnel (Heitz et al. 2016, supplemental; Hill and Heitz 2016).
inline float ltcFresnelMagnitude(const LtcCoefficients& ltc, float f0) {
  return f0 * ltc.norm + (1.0f - f0) * ltc.fresnel;
}

}  // namespace glintbake::runtime
