// SPDX-License-Identifier: Apache-2.0
// Linearly transformed cosines (Heitz, Dupuy, Hill and Neubelt 2016, "Real-Time Polygonal-Light
// Shading with Linearly Transformed Cosines") and the microfacet BRDFs they approximate.
//
// Directions live in the local shading frame of a fit cell: z = surface normal, the view direction
// V lies in the x-z half plane with V.x >= 0. All functions are pure and thread-safe.
#pragma once

#include <glintbake/format/numbers.h>

#include <cmath>
#include <cstdint>
#include <string>

namespace glintbake::bake::ltc {

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
};
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double length(Vec3 a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(Vec3 a) { return (1.0 / length(a)) * a; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// Row-major 3x3 matrix: m[row][col].
struct Mat3 {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  Vec3 operator*(Vec3 v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
};
Mat3 operator*(const Mat3& a, const Mat3& b);
double determinant(const Mat3& a);
// Inverse by the adjugate; the caller guarantees a non-singular matrix.
Mat3 inverse(const Mat3& a);

// The microfacet BRDFs the tables approximate. Both use the height-correlated Smith masking-
// shadowing term G2 = 1 / (1 + Lambda(V) + Lambda(L)) (Heitz 2014, "Understanding the
// Masking-Shadowing Function", eq. 99).
enum class BrdfKind : uint32_t { kGgx = 0, kBeckmann = 1 };
const char* brdfKindString(BrdfKind kind);  // "ggx", "beckmann"
bool brdfKindFromString(const std::string& name, BrdfKind* kind);

// BRDF times cos(theta_L) for view V (V.z > 0) and light L, both unit vectors, roughness alpha > 0
// (the distribution's width parameter, alpha = roughness^2 in the table parametrisation).
// *pdf receives the density (per solid angle of L) of sampleBrdf(): D(H) H.z / (4 |V.H|), also for
// L below the horizon, where the returned value is 0.
double evalBrdf(BrdfKind kind, Vec3 v, Vec3 l, double alpha, double* pdf);
// Reflects V about a normal drawn from D(H) H.z with uniform numbers u1, u2 in [0, 1). The result
// may point below the horizon (its BRDF value is then 0).
Vec3 sampleBrdf(BrdfKind kind, Vec3 v, double alpha, double u1, double u2);

// One linearly transformed cosine D(L) = D_o(normalize(M^-1 L)) |det M^-1| / |M^-1 L|^3 with
// D_o(w) = max(0, w.z) / pi, scaled by `magnitude`. M = [X Y Z] * [[m11, 0, m13], [0, m22, 0],
// [0, 0, 1]] as in Heitz et al. 2016 (supplemental fitting code).
struct Ltc {
  double magnitude = 1.0;
  double fresnel = 1.0;
  double m11 = 1.0, m22 = 1.0, m13 = 0.0;
  Vec3 x_axis{1, 0, 0}, y_axis{0, 1, 0}, z_axis{0, 0, 1};
  Mat3 m, inv_m;
  double det_inv_m = 1.0;  // |det M^-1|

  // Recomputes m, inv_m and det_inv_m from the parameters and axes.
  void update();
  // Builds an LTC directly from an inverse matrix (any scale: the distribution is scale-invariant).
  static Ltc fromInverse(const Mat3& inverse_matrix, double magnitude);
  // magnitude * D(L) for a unit direction L.
  double eval(Vec3 l) const;
  // Density of sample() at L (D(L), without magnitude).
  double pdf(Vec3 l) const { return eval(l) / magnitude; }
  // Draws L = normalize(M w) with w cosine-distributed from u1, u2 in [0, 1).
  Vec3 sample(double u1, double u2) const;
};

}  // namespace glintbake::bake::ltc
