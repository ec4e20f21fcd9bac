// SPDX-License-Identifier: Apache-2.0
// Rank sums of the CP queries with four independent accumulators (term r goes to lane r % 4).
// Float addition is not associative, so a plain loop is compiled as one chain of dependent scalar
// additions; four lanes let the compiler keep the partial sums in one SIMD register. The order of
// the additions is fixed, so results are the same on every call (internal to the runtime).
#pragma once

#include <cstdint>

#if defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#include <emmintrin.h>
#define GLINTBAKE_RUNTIME_SSE2 1
#else
#define GLINTBAKE_RUNTIME_SSE2 0
#endif

namespace glintbake::runtime {

// lanes[k] += w * sum_{r < n, r % 4 == k} term(r): the per-lane partial sums of one term set,
// weighted, added to running lanes (several weighted sums then share one final reduction).
template <typename T, typename Term>
inline void laneAccumulate(int32_t n, Term term, T w, T lanes[4]) {
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
  lanes[0] += w * s0;
  lanes[1] += w * s1;
  lanes[2] += w * s2;
  lanes[3] += w * s3;
}

// lanes[k] += w * sum_{r % 4 == k} a[r] b[r] c[r] in float: laneAccumulate of the triple product,
// with one SSE2 register as the four lanes when n is a multiple of 4 (every lane sees the same
// additions in the same order, so both paths give the same bits).
#if GLINTBAKE_RUNTIME_SSE2
// The four lane sums of a[r] b[r] c[r] for n a multiple of 4, in one register.
inline __m128 laneDot3Sse(const float* a, const float* b, const float* c, int32_t n) {
  auto term = [=](int32_t r) {
    return _mm_mul_ps(_mm_mul_ps(_mm_loadu_ps(a + r), _mm_loadu_ps(b + r)), _mm_loadu_ps(c + r));
  };
  __m128 s = _mm_setzero_ps();
  if (n == 16) {  // the default rank, unrolled (same additions, same order)
    s = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_add_ps(s, term(0)), term(4)), term(8)), term(12));
  } else {
    for (int32_t r = 0; r < n; r += 4) s = _mm_add_ps(s, term(r));
  }
  return s;
}
#endif

inline void laneAccumulateDot3(const float* a, const float* b, const float* c, int32_t n, float w, float lanes[4]) {
#if GLINTBAKE_RUNTIME_SSE2
  if ((n & 3) == 0) {
    _mm_storeu_ps(lanes, _mm_add_ps(_mm_loadu_ps(lanes), _mm_mul_ps(_mm_set1_ps(w), laneDot3Sse(a, b, c, n))));
    return;
  }
#endif
  laneAccumulate<float>(
      n, [=](int32_t r) { return a[r] * b[r] * c[r]; }, w, lanes);
}

// Running lanes of laneAccumulateDot3 kept in a register between terms (the same additions, so
// the same bits as a float[4]): a sum over hundreds of terms does not store and reload its lanes
// for every term.
class Dot3Lanes {
 public:
  void add(const float* a, const float* b, const float* c, int32_t n, float w) {
#if GLINTBAKE_RUNTIME_SSE2
    if ((n & 3) == 0) {
      v_ = _mm_add_ps(v_, _mm_mul_ps(_mm_set1_ps(w), laneDot3Sse(a, b, c, n)));
      return;
    }
    float lanes[4];
    _mm_storeu_ps(lanes, v_);
    laneAccumulateDot3(a, b, c, n, w, lanes);
    v_ = _mm_loadu_ps(lanes);
#else
    laneAccumulateDot3(a, b, c, n, w, v_);
#endif
  }
  // (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]), as laneTotal.
  float total() const {
#if GLINTBAKE_RUNTIME_SSE2
    float lanes[4];
    _mm_storeu_ps(lanes, v_);
    return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
#else
    return (v_[0] + v_[1]) + (v_[2] + v_[3]);
#endif
  }

 private:
#if GLINTBAKE_RUNTIME_SSE2
  __m128 v_ = _mm_setzero_ps();
#else
  float v_[4] = {0.0f, 0.0f, 0.0f, 0.0f};
#endif
};

template <typename T>
inline T laneTotal(const T lanes[4]) {
  return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

// sum_{r < n} term(r), in T.
template <typename T, typename Term>
inline T laneSum(int32_t n, Term term) {
  T lanes[4] = {T(0), T(0), T(0), T(0)};
  laneAccumulate<T>(n, term, T(1), lanes);  // w = 1 and 0 + x are exact
  return laneTotal(lanes);
}

// sum_r a[r] * b[r] * c[r] (laneAccumulateDot3 with w = 1 into zero lanes: exact, same bits).
inline float laneDot3(const float* a, const float* b, const float* c, int32_t n) {
  float lanes[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  laneAccumulateDot3(a, b, c, n, 1.0f, lanes);
  return laneTotal(lanes);
}

// sum_r a[r] * b[r]
inline float laneDot(const float* a, const float* b, int32_t n) {
  return laneSum<float>(n, [=](int32_t r) { return a[r] * b[r]; });
}

}  // namespace glintbake::runtime
