// SPDX-License-Identifier: Apache-2.0
// Record status names and the binary16 codec.
#include <glintbake/format/binary16.h>
#include <glintbake/format/records.h>

#include <cmath>
#include <cstring>

namespace glintbake::format {

const char* recordStatusString(RecordStatus status) {
  switch (status) {
    case RecordStatus::kOk:
      return "ok";
    case RecordStatus::kBadMagic:
      return "bad magic";
    case RecordStatus::kUnsupportedVersion:
      return "unsupported record version";
    case RecordStatus::kInvalid:
      return "invalid record";
  }
  return "unknown record status";
}

uint16_t floatToHalf(float value) {
  uint32_t x;
  std::memcpy(&x, &value, sizeof(x));
  const uint32_t sign = (x >> 16) & 0x8000u;
  const uint32_t mag = x & 0x7FFFFFFFu;
  if (mag >= 0x7F800000u) return uint16_t(sign | (mag > 0x7F800000u ? 0x7E00u : 0x7C00u));  // NaN, infinity
  if (mag >= 0x477FF000u) return uint16_t(sign | 0x7C00u);  // >= 65520 rounds to infinity
  if (mag < 0x38800000u) {
    // Below 2^-14: a subnormal half, an integer multiple of 2^-24. Scaling by 2^24 is exact, and
    // nearbyint rounds half to even in the default rounding mode.
    float magnitude;
    std::memcpy(&magnitude, &mag, sizeof(magnitude));
    return uint16_t(sign | uint32_t(std::nearbyint(magnitude * 16777216.0f)));
  }
  // Normal: rebias the exponent, keep 10 mantissa bits, round the 13 dropped bits to nearest even
  // (a carry out of the mantissa correctly bumps the exponent).
  uint32_t h = (((mag >> 23) - 127u + 15u) << 10) | ((mag & 0x7FFFFFu) >> 13);
  const uint32_t rest = mag & 0x1FFFu;
  if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;
  return uint16_t(sign | h);
}

float halfToFloat(uint16_t bits) {
  const uint32_t sign = uint32_t(bits & 0x8000u) << 16;
  const uint32_t e = (bits >> 10) & 0x1Fu;
  const uint32_t m = bits & 0x3FFu;
  uint32_t x;
  if (e == 0) {
    const float v = float(m) * (1.0f / 16777216.0f);  // subnormal or zero, exact
    std::memcpy(&x, &v, sizeof(x));
    x |= sign;
  } else if (e == 31) {
    x = sign | 0x7F800000u | (m << 13);
  } else {
    x = sign | ((e - 15u + 127u) << 23) | (m << 13);
  }
  float out;
  std::memcpy(&out, &x, sizeof(out));
  return out;
}

}  // namespace glintbake::format
