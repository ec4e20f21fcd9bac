// Rank sums of the CP queries with four independent accumulators (term r goes to lane r % 4).
// Float addition is not associative, so a plain loop is compiled as one chain of dependent scalar
// additions; four lanes let the compiler keep the partial sums in one SIMD register. The order of
// the additions is fixed, so results are the same on every call (internal to the runtime).
#pragma once

#include <cstdint>

namespace glintbake::runtime {

// sum_r a[r] * b[r] * c[r]
template <typename T, typename U>
inline T laneDot3(const T* a, const U* b, const U* c, int32_t n) {
  T s0 = T(0), s1 = T(0), s2 = T(0), s3 = T(0);
  int32_t r = 0;
  for (; r + 4 <= n; r += 4) {
    s0 += a[r] * T(b[r]) * T(c[r]);
    s1 += a[r + 1] * T(b[r + 1]) * T(c[r + 1]);
    s2 += a[r + 2] * T(b[r + 2]) * T(c[r + 2]);
    s3 += a[r + 3] * T(b[r + 3]) * T(c[r + 3]);
  }
  if (r < n) s0 += a[r] * T(b[r]) * T(c[r]);
  if (r + 1 < n) s1 += a[r + 1] * T(b[r + 1]) * T(c[r + 1]);
  if (r + 2 < n) s2 += a[r + 2] * T(b[r + 2]) * T(c[r + 2]);
  return (s0 + s1) + (s2 + s3);
}

// sum_r a[r] * b[r]
template <typename T, typename U>
inline T laneDot(const T* a, const U* b, int32_t n) {
  T s0 = T(0), s1 = T(0), s2 = T(0), s3 = T(0);
  int32_t r = 0;
  for (; r + 4 <= n; r += 4) {
    s0 += a[r] * T(b[r]);
    s1 += a[r + 1] * T(b[r + 1]);
    s2 += a[r + 2] * T(b[r + 2]);
    s3 += a[r + 3] * T(b[r + 3]);
  }
  if (r < n) s0 += a[r] * T(b[r]);
  if (r + 1 < n) s1 += a[r + 1] * T(b[r + 1]);
  if (r + 2 < n) s2 += a[r + 2] * T(b[r + 2]);
  return (s0 + s1) + (s2 + s3);
}

}  // namespace glintbake::runtime
