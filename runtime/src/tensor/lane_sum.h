// Rank sums of the CP queries with four independent accumulators (term r goes to lane r % 4).
// Float addition is not associative, so a plain loop is compiled as one chain of dependent scalar
// additions; four lanes let the compiler keep the partial sums in one SIMD register. The order of
// the additions is fixed, so results are the same on every call (internal to the runtime).
#pragma once

#include <cstdint>

namespace glintbake::runtime {

// sum_{r < n} term(r), in T.
template <typename T, typename Term>
inline T laneSum(int32_t n, Term term) {
  T s0 = T(0), s1 = T(0), s2 = T(0), s3 = T(0);
  int32_t r = 0;
  for (; r + 4 <= n; r += 4) {
    s0 += term(r);
    s1 += term(r + 1);
    s2 += term(r + 2);
    s3 += term(r + 3);
  }
  if (r < n) s0 += term(r);
  if (r + 1 < n) s1 += term(r + 1);
  if (r + 2 < n) s2 += term(r + 2);
  return (s0 + s1) + (s2 + s3);
}

// sum_r a[r] * b[r] * c[r]
template <typename T, typename U>
inline T laneDot3(const T* a, const U* b, const U* c, int32_t n) {
  return laneSum<T>(n, [=](int32_t r) { return a[r] * T(b[r]) * T(c[r]); });
}

// sum_r a[r] * b[r]
template <typename T, typename U>
inline T laneDot(const T* a, const U* b, int32_t n) {
  return laneSum<T>(n, [=](int32_t r) { return a[r] * T(b[r]); });
}

}  // namespace glintbake::runtime
