// SPDX-License-Identifier: Apache-2.0
// IEEE 754 binary16 ("half") conversion, the one codec every writer and reader of float16 section
// data uses (tensor-ndf factors, formats/SPEC.md 10.4).
#pragma once

#include <cstdint>

namespace glintbake::format {

// Rounds to the nearest binary16, ties to even; values of magnitude >= 65520 become infinity,
// NaN stays NaN (quiet). Exact for every value a binary16 can hold.
uint16_t floatToHalf(float value);
// Exact: every binary16 value (subnormals, infinities, NaN payloads) is a binary32 value.
float halfToFloat(uint16_t bits);

}  // namespace glintbake::format
