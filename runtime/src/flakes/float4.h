// SPDX-License-Identifier: Apache-2.0
// Four float lanes for the flake evaluator's inner loop (internal to the runtime): one SSE2
// register where the target has it, a plain array elsewhere. Every operation is the same IEEE
// single-precision operation lane by lane in both forms (no fused multiply-add, exp4 written out
// of those operations), so both give the same bits.
#pragma once

#include <cstdint>
#include <cstring>

#if defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#include <emmintrin.h>
#define GLINTBAKE_FLAKES_SSE2 1
#else
#define GLINTBAKE_FLAKES_SSE2 0
#endif

namespace glintbake::runtime::flakes {

#if GLINTBAKE_FLAKES_SSE2
struct F4 {
  static constexpr int kWidth = 4;
  __m128 v;
  static F4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  static F4 splat(float x) { return {_mm_set1_ps(x)}; }
  friend F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend F4 operator-(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend F4 operator*(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend F4 operator/(F4 a, F4 b) { return {_mm_div_ps(a.v, b.v)}; }
  friend F4 sqrt(F4 a) { return {_mm_sqrt_ps(a.v)}; }
  friend F4 max(F4 a, F4 b) { return {_mm_max_ps(a.v, b.v)}; }
  // Lanes where a < b keep x, the others become 0.
  friend F4 selectLess(F4 a, F4 b, F4 x) { return {_mm_and_ps(_mm_cmplt_ps(a.v, b.v), x.v)}; }
  friend bool anyLess(F4 a, F4 b) { return _mm_movemask_ps(_mm_cmplt_ps(a.v, b.v)) != 0; }
  // Bit i set where lane i has a <= b (a < b).
  friend int lessEqualMask(F4 a, F4 b) { return _mm_movemask_ps(_mm_cmple_ps(a.v, b.v)); }
  friend int lessMask(F4 a, F4 b) { return _mm_movemask_ps(_mm_cmplt_ps(a.v, b.v)); }
  // The lanes of x whose bit is set in mask, in order, at dst[0..) (writes kWidth floats).
  friend void compressStore(float* dst, F4 x, int mask) {
    float l[4];
    x.store(l);
    int c = 0;
    for (int i = 0; i < 4; ++i) {
      dst[c] = l[i];
      c += (mask >> i) & 1;
    }
  }
  // Four bytes as floats.
  static F4 fromBytes(const uint8_t* p) {
    int32_t word;
    std::memcpy(&word, p, 4);
    const __m128i zero = _mm_setzero_si128();
    const __m128i b = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(word), zero), zero);
    return {_mm_cvtepi32_ps(b)};
  }
  // floor for |x| < 2^31.
  friend F4 floor4(F4 x) {
    const __m128 t = _mm_cvtepi32_ps(_mm_cvttps_epi32(x.v));
    return {_mm_sub_ps(t, _mm_and_ps(_mm_cmpgt_ps(t, x.v), _mm_set1_ps(1.0f)))};
  }
  // 2^n for integral n in [-126, 127].
  friend F4 pow2i(F4 n) {
    return {_mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(_mm_cvttps_epi32(n.v), _mm_set1_epi32(127)), 23))};
  }
  void store(float* p) const { _mm_storeu_ps(p, v); }
};
#else
struct F4 {
  static constexpr int kWidth = 4;
  float v[4];
  static F4 load(const float* p) {
    F4 r;
    for (int i = 0; i < 4; ++i) r.v[i] = p[i];
    return r;
  }
  static F4 splat(float x) { return {{x, x, x, x}}; }
  template <typename Op>
  static F4 map(F4 a, F4 b, Op op) {
    F4 r;
    for (int i = 0; i < 4; ++i) r.v[i] = op(a.v[i], b.v[i]);
    return r;
  }
  friend F4 operator+(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x + y; });
  }
  friend F4 operator-(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x - y; });
  }
  friend F4 operator*(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x * y; });
  }
  friend F4 operator/(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x / y; });
  }
  friend F4 sqrt(F4 a) {
    F4 r;
    for (int i = 0; i < 4; ++i) r.v[i] = __builtin_sqrtf(a.v[i]);
    return r;
  }
  friend F4 max(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return y > x ? y : x; });
  }
  friend F4 selectLess(F4 a, F4 b, F4 x) {
    F4 r;
    for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] < b.v[i] ? x.v[i] : 0.0f;
    return r;
  }
  friend bool anyLess(F4 a, F4 b) {
    for (int i = 0; i < 4; ++i)
      if (a.v[i] < b.v[i]) return true;
    return false;
  }
  friend int lessEqualMask(F4 a, F4 b) {
    int m = 0;
    for (int i = 0; i < 4; ++i) m |= (a.v[i] <= b.v[i] ? 1 : 0) << i;
    return m;
  }
  friend int lessMask(F4 a, F4 b) {
    int m = 0;
    for (int i = 0; i < 4; ++i) m |= (a.v[i] < b.v[i] ? 1 : 0) << i;
    return m;
  }
  friend void compressStore(float* dst, F4 x, int mask) {
    int c = 0;
    for (int i = 0; i < 4; ++i) {
      dst[c] = x.v[i];
      c += (mask >> i) & 1;
    }
  }
  static F4 fromBytes(const uint8_t* p) {
    F4 r;
    for (int i = 0; i < 4; ++i) r.v[i] = float(p[i]);
    return r;
  }
  friend F4 floor4(F4 x) {
    F4 r;
    for (int i = 0; i < 4; ++i) {
      const float t = float(int32_t(x.v[i]));
      r.v[i] = t > x.v[i] ? t - 1.0f : t;
    }
    return r;
  }
  friend F4 pow2i(F4 n) {
    F4 r;
    for (int i = 0; i < 4; ++i) {
      const uint32_t bits = uint32_t(int32_t(n.v[i]) + 127) << 23;
      std::memcpy(&r.v[i], &bits, 4);
    }
    return r;
  }
  void store(float* p) const {
    for (int i = 0; i < 4; ++i) p[i] = v[i];
  }
};
#endif

inline F4 floorV(F4 x) { return floor4(x); }

// Set bits of a lane mask (eight lanes at most).
inline int maskCount(int m) {
  m = (m & 0x55) + ((m >> 1) & 0x55);
  m = (m & 0x33) + ((m >> 2) & 0x33);
  return (m & 0x0f) + ((m >> 4) & 0x0f);
}

// |x| lane by lane.
inline F4 abs4(F4 x) { return max(x, F4::splat(0.0f) - x); }

// A hint to bring the cache line holding p closer (no effect on results).
inline void prefetch(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(p);
#elif GLINTBAKE_FLAKES_SSE2
  _mm_prefetch(static_cast<const char*>(p), _MM_HINT_T0);
#else
  (void)p;
#endif
}

// e^-x for x in [0, 87] (larger x gives e^-87), relative error about 2e-7: range reduction by
// ln 2 in two parts and a degree-6 polynomial (the classic single-precision expf coefficients).
inline F4 expNeg4(F4 x) {
  F4 y = F4::splat(0.0f) - x;
  y = max(y, F4::splat(-87.0f));
  const F4 n = floor4(y * F4::splat(1.44269504088896341f) + F4::splat(0.5f));
  F4 r = y - n * F4::splat(0.693359375f);
  r = r - n * F4::splat(-2.12194440e-4f);
  const F4 r2 = r * r;
  F4 p = F4::splat(1.9875691500e-4f);
  p = p * r + F4::splat(1.3981999507e-3f);
  p = p * r + F4::splat(8.3334519073e-3f);
  p = p * r + F4::splat(4.1665795894e-2f);
  p = p * r + F4::splat(1.6666665459e-1f);
  p = p * r + F4::splat(5.0000001201e-1f);
  p = p * r2 + r + F4::splat(1.0f);
  return p * pow2i(n);
}

}  // namespace glintbake::runtime::flakes
