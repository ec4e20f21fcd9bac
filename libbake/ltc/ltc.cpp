// SPDX-License-Identifier: Apache-2.0
// Microfacet BRDFs and linearly transformed cosines: evaluation and sampling.
#include <glintbake/bake/ltc/ltc.h>

#include <algorithm>

namespace glintbake::bake::ltc {

Mat3 operator*(const Mat3& a, const Mat3& b) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return r;
}

double determinant(const Mat3& a) {
  const auto& m = a.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

Mat3 inverse(const Mat3& a) {
  const auto& m = a.m;
  const double inv_det = 1.0 / determinant(a);
  Mat3 r;
  r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * inv_det;
  r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv_det;
  r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv_det;
  r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * inv_det;
  r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv_det;
  r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv_det;
  r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * inv_det;
  r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv_det;
  r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv_det;
  return r;
}

const char* brdfKindString(BrdfKind kind) {
  switch (kind) {
    case BrdfKind::kGgx:
      return "ggx";
    case BrdfKind::kBeckmann:
      return "beckmann";
  }
  return "unknown";
}

bool brdfKindFromString(const std::string& name, BrdfKind* kind) {
  if (name == "ggx") {
    *kind = BrdfKind::kGgx;
  } else if (name == "beckmann") {
    *kind = BrdfKind::kBeckmann;
  } else {
    return false;
  }
  return true;
}

namespace {

// Smith Lambda for a direction with cosine c, written with a = 1 / (alpha tan theta) as
// 1/a^2 = alpha^2 (1 - c^2) / c^2 so that no trigonometric function is needed.
double lambdaGgx(double alpha, double c) {
  if (c >= 1.0) return 0.0;
  const double inv_a2 = alpha * alpha * (1.0 - c * c) / (c * c);
  return 0.5 * (-1.0 + std::sqrt(1.0 + inv_a2));
}

// Beckmann Lambda by Walter et al. 2007's rational approximation (eq. 27).
double lambdaBeckmann(double alpha, double c) {
  if (c >= 1.0) return 0.0;
  const double a = c / (alpha * std::sqrt(1.0 - c * c));
  if (a >= 1.6) return 0.0;
  return (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
}

}  // namespace

double evalBrdf(BrdfKind kind, Vec3 v, Vec3 l, double alpha, double* pdf) {
  *pdf = 0.0;
  if (v.z <= 0.0) return 0.0;
  const Vec3 sum = v + l;
  const double sum_len = length(sum);
  if (!(sum_len > 0.0)) return 0.0;
  const Vec3 h = (1.0 / sum_len) * sum;
  if (!(h.z > 0.0)) return 0.0;
  const double hz2 = h.z * h.z;
  const double slope2 = (h.x * h.x + h.y * h.y) / hz2;  // tan^2 of the half-vector angle
  const double a2 = alpha * alpha;
  double d;
  if (kind == BrdfKind::kGgx) {
    const double t = 1.0 + slope2 / a2;
    d = 1.0 / (kPi * a2 * hz2 * hz2 * t * t);
  } else {
    d = std::exp(-slope2 / a2) / (kPi * a2 * hz2 * hz2);
  }
  const double vh = std::abs(dot(v, h));
  *pdf = vh > 0.0 ? d * h.z / (4.0 * vh) : 0.0;
  if (l.z <= 0.0) return 0.0;
  const double lambda_v = kind == BrdfKind::kGgx ? lambdaGgx(alpha, v.z) : lambdaBeckmann(alpha, v.z);
  const double lambda_l = kind == BrdfKind::kGgx ? lambdaGgx(alpha, l.z) : lambdaBeckmann(alpha, l.z);
  const double g2 = 1.0 / (1.0 + lambda_v + lambda_l);
  // D G2 / (4 V.z L.z) times L.z.
  return d * g2 / (4.0 * v.z);
}

Vec3 sampleBrdf(BrdfKind kind, Vec3 v, double alpha, double u1, double u2) {
  const double phi = 2.0 * kPi * u1;
  const double r =
      kind == BrdfKind::kGgx ? alpha * std::sqrt(u2 / (1.0 - u2)) : std::sqrt(-alpha * alpha * std::log(1.0 - u2));
  const Vec3 n = normalize(Vec3{r * std::cos(phi), r * std::sin(phi), 1.0});
  return 2.0 * dot(n, v) * n - v;
}

void Ltc::update() {
  Mat3 axes;
  axes.m[0][0] = x_axis.x, axes.m[1][0] = x_axis.y, axes.m[2][0] = x_axis.z;
  axes.m[0][1] = y_axis.x, axes.m[1][1] = y_axis.y, axes.m[2][1] = y_axis.z;
  axes.m[0][2] = z_axis.x, axes.m[1][2] = z_axis.y, axes.m[2][2] = z_axis.z;
  Mat3 params;
  params.m[0][0] = m11;
  params.m[1][1] = m22;
  params.m[0][2] = m13;
  m = axes * params;
  inv_m = inverse(m);
  det_inv_m = std::abs(determinant(inv_m));
}

Ltc Ltc::fromInverse(const Mat3& inverse_matrix, double magnitude) {
  Ltc ltc;
  ltc.magnitude = magnitude;
  ltc.inv_m = inverse_matrix;
  ltc.m = inverse(inverse_matrix);
  ltc.det_inv_m = std::abs(determinant(inverse_matrix));
  return ltc;
}

double Ltc::eval(Vec3 l) const {
  const Vec3 lo = inv_m * l;
  const double len = length(lo);
  const double d = std::max(0.0, lo.z / len) / kPi;
  return magnitude * d * det_inv_m / (len * len * len);
}

Vec3 Ltc::sample(double u1, double u2) const {
  const double cos_theta = std::sqrt(u1);
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - u1));
  const double phi = 2.0 * kPi * u2;
  return normalize(m * Vec3{sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta});
}

}  // namespace glintbake::bake::ltc
