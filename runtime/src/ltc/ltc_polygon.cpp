// SPDX-License-Identifier: Apache-2.0
// Runtime-lite LTC polygon integration: transform, clip to the horizon, integrate edge by edge.
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/ltc.h>

#include <algorithm>
#include <cmath>

namespace glintbake::runtime {

namespace {

// Clipping a polygon against a plane emits at most two vertices per input edge.
constexpr int kClipBuffer = 2 * kLtcMaxPolygonVertices;

struct V3 {
  double x, y, z;
};

double dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Sutherland-Hodgman clip of a closed polygon against z >= 0; returns the vertex count.
int clipToHorizon(const V3* in, int count, V3* out) {
  int n = 0;
  for (int i = 0; i < count; ++i) {
    const V3 a = in[i];
    const V3 b = in[(i + 1) % count];
    const bool a_in = a.z >= 0.0;
    const bool b_in = b.z >= 0.0;
    if (a_in) out[n++] = a;
    if (a_in != b_in) {
      const double t = a.z / (a.z - b.z);
      out[n++] = {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), 0.0};
    }
  }
  return n;
}

// Integral of the clamped cosine / pi over the spherical polygon with the given (unnormalised)
// vertices, all in z >= 0: sum of the edges' theta * normalize(v1 x v2).z / (2 pi).
double integrateClipped(V3* p, int n) {
  for (int i = 0; i < n; ++i) {
    const double len = std::sqrt(dot3(p[i], p[i]));
    if (!(len > 0.0)) return 0.0;
    p[i] = {p[i].x / len, p[i].y / len, p[i].z / len};
  }
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const V3 a = p[i];
    const V3 b = p[(i + 1) % n];
    const V3 c = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    const double sin_theta = std::sqrt(dot3(c, c));
    if (!(sin_theta > 0.0)) continue;
    const double theta = std::atan2(sin_theta, dot3(a, b));
    sum += theta * c.z / sin_theta;
  }
  return sum / kTwoPi;
}

float integrate(const double m[3][3], const float (*vertices)[3], int count, bool two_sided) {
  if (!vertices || count < 3 || count > kLtcMaxPolygonVertices) return 0.0f;
  V3 transformed[kLtcMaxPolygonVertices];
  for (int i = 0; i < count; ++i) {
    const double x = vertices[i][0], y = vertices[i][1], z = vertices[i][2];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return 0.0f;
    transformed[i] = {m[0][0] * x + m[0][1] * y + m[0][2] * z, m[1][0] * x + m[1][1] * y + m[1][2] * z,
                      m[2][0] * x + m[2][1] * y + m[2][2] * z};
  }
  V3 clipped[kClipBuffer];
  const int n = clipToHorizon(transformed, count, clipped);
  if (n < 3) return 0.0f;
  const double sum = integrateClipped(clipped, n);
  return float(two_sided ? std::abs(sum) : std::max(0.0, sum));
}

}  // namespace

void ltcShadingFrame(const float n[3], const float v[3], float x[3], float y[3], float z[3]) {
  const double d = double(n[0]) * v[0] + double(n[1]) * v[1] + double(n[2]) * v[2];
  double t[3] = {v[0] - d * n[0], v[1] - d * n[1], v[2] - d * n[2]};
  double len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  if (!(len > 1e-12)) {
    // V along N: any perpendicular axis (the LTC is rotationally symmetric there).
    const double a[3] = {std::abs(n[0]) < 0.9f ? 1.0 : 0.0, std::abs(n[0]) < 0.9f ? 0.0 : 1.0, 0.0};
    const double e = a[0] * n[0] + a[1] * n[1];
    t[0] = a[0] - e * n[0], t[1] = a[1] - e * n[1], t[2] = -e * n[2];
    len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  }
  for (int i = 0; i < 3; ++i) {
    x[i] = float(t[i] / len);
    z[i] = n[i];
  }
  y[0] = z[1] * x[2] - z[2] * x[1];
  y[1] = z[2] * x[0] - z[0] * x[2];
  y[2] = z[0] * x[1] - z[1] * x[0];
}

float ltcCosTheta(const float n[3], const float v[3]) {
  return std::clamp(n[0] * v[0] + n[1] * v[1] + n[2] * v[2], 0.0f, 1.0f);
}

float ltcIntegratePolygon(const LtcCoefficients& ltc, const float (*vertices)[3], int count, bool two_sided) {
  double m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = ltc.inv_m[r][c];
  return integrate(m, vertices, count, two_sided);
}

float ltcFormFactor(const float (*vertices)[3], int count, bool two_sided) {
  const double identity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  return integrate(identity, vertices, count, two_sided);
}

}  // namespace glintbake::runtime
