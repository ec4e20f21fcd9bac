// SPDX-License-Identifier: Apache-2.0
// Eight float lanes in one AVX2 register for the flake and lobe kernels (internal to the runtime).
// Only x86-64 with GCC or Clang has them (GLINTBAKE_FLAKES_AVX2); the build needs no -march flag:
// F8 and the kernels instantiated with it are compiled for AVX2 by a target pragma between
// GLINTBAKE_FLAKES_AVX2_BEGIN and GLINTBAKE_FLAKES_AVX2_END, and run only where the processor has
// AVX2 (flakes::hasAvx2()). No fused multiply-add: every operation is the IEEE single-precision
// operation of F4 lane by lane, so both give the same bits.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define GLINTBAKE_FLAKES_AVX2 1
#include <immintrin.h>
#else
#define GLINTBAKE_FLAKES_AVX2 0
#endif

#include <atomic>
#include <cstdint>

#if GLINTBAKE_FLAKES_AVX2
#if defined(__clang__)
#define GLINTBAKE_FLAKES_AVX2_BEGIN \
  _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define GLINTBAKE_FLAKES_AVX2_END _Pragma("clang attribute pop")
#else
#define GLINTBAKE_FLAKES_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define GLINTBAKE_FLAKES_AVX2_END _Pragma("GCC pop_options")
#endif
// Spelled out on F8's members too (GCC does not extend the pragma to functions defined in a class).
#define GLINTBAKE_AVX2_FN __attribute__((target("avx2")))
#endif

namespace glintbake::runtime::flakes {

// Whether the kernels may use AVX2: the processor has it and no caller asked for the portable
// kernels (selectPortableKernels, for tests and benchmarks).
std::atomic<bool>& portableKernelsOnly();
inline bool hasAvx2() {
#if GLINTBAKE_FLAKES_AVX2
  static const bool has = __builtin_cpu_supports("avx2");
  return has && !portableKernelsOnly().load(std::memory_order_relaxed);
#else
  return false;
#endif
}

}  // namespace glintbake::runtime::flakes

#if GLINTBAKE_FLAKES_AVX2
GLINTBAKE_FLAKES_AVX2_BEGIN
namespace glintbake::runtime::flakes {

// For every mask of eight lanes, the indices of its set lanes in order (then zeros).
struct CompressTable {
  uint8_t index[256][8];
  constexpr CompressTable() : index() {
    for (int m = 0; m < 256; ++m) {
      int c = 0;
      for (int i = 0; i < 8; ++i)
        if ((m >> i) & 1) index[m][c++] = uint8_t(i);
    }
  }
};
inline constexpr CompressTable kCompressTable{};

struct F8 {
  static constexpr int kWidth = 8;
  __m256 v;
  GLINTBAKE_AVX2_FN static F8 load(const float* p) { return {_mm256_loadu_ps(p)}; }
  GLINTBAKE_AVX2_FN static F8 splat(float x) { return {_mm256_set1_ps(x)}; }
  // Eight bytes as floats.
  GLINTBAKE_AVX2_FN static F8 fromBytes(const uint8_t* p) {
    return {_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))))};
  }
  GLINTBAKE_AVX2_FN friend F8 operator+(F8 a, F8 b) { return {_mm256_add_ps(a.v, b.v)}; }
  GLINTBAKE_AVX2_FN friend F8 operator-(F8 a, F8 b) { return {_mm256_sub_ps(a.v, b.v)}; }
  GLINTBAKE_AVX2_FN friend F8 operator*(F8 a, F8 b) { return {_mm256_mul_ps(a.v, b.v)}; }
  GLINTBAKE_AVX2_FN friend F8 operator/(F8 a, F8 b) { return {_mm256_div_ps(a.v, b.v)}; }
  GLINTBAKE_AVX2_FN friend F8 sqrt(F8 a) { return {_mm256_sqrt_ps(a.v)}; }
  GLINTBAKE_AVX2_FN friend F8 max(F8 a, F8 b) { return {_mm256_max_ps(a.v, b.v)}; }
  GLINTBAKE_AVX2_FN friend F8 selectLess(F8 a, F8 b, F8 x) {
    return {_mm256_and_ps(_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ), x.v)};
  }
  GLINTBAKE_AVX2_FN friend int lessMask(F8 a, F8 b) { return _mm256_movemask_ps(_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)); }
  GLINTBAKE_AVX2_FN friend int lessEqualMask(F8 a, F8 b) {
    return _mm256_movemask_ps(_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ));
  }
  GLINTBAKE_AVX2_FN friend F8 floorV(F8 x) {
    const __m256 t = _mm256_cvtepi32_ps(_mm256_cvttps_epi32(x.v));
    return {_mm256_sub_ps(t, _mm256_and_ps(_mm256_cmp_ps(t, x.v, _CMP_GT_OQ), _mm256_set1_ps(1.0f)))};
  }
  GLINTBAKE_AVX2_FN friend F8 pow2i(F8 n) {
    return {
        _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_add_epi32(_mm256_cvttps_epi32(n.v), _mm256_set1_epi32(127)), 23))};
  }
  // The lanes of x whose bit is set in mask, in order, at dst[0..) (writes kWidth floats).
  GLINTBAKE_AVX2_FN friend void compressStore(float* dst, F8 x, int mask) {
    const __m256i index =
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(kCompressTable.index[mask])));
    _mm256_storeu_ps(dst, _mm256_permutevar8x32_ps(x.v, index));
  }
  GLINTBAKE_AVX2_FN void store(float* p) const { _mm256_storeu_ps(p, v); }
};

}  // namespace glintbake::runtime::flakes
GLINTBAKE_FLAKES_AVX2_END
#endif
