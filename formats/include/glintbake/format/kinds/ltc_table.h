// SPDX-License-Identifier: Apache-2.0
// Sections of ltc-table assets (formats/SPEC.md section 10.2), written by libbake's LTC table
// writer (ltcfit table), read by the runtime's LtcTable: two image sections of type 48.
#pragma once

#include <cstdint>

namespace glintbake::format {

constexpr uint64_t kLtcTableKeyMatrix = 0;     // `ltc_1`: N x N x 4 (m00, m20, m02, m22) of the normalised inverse
constexpr uint64_t kLtcTableKeyAmplitude = 1;  // `ltc_2`: N x N x 4 (norm, fresnel, 0, sphere)
constexpr uint32_t kLtcTableChannels = 4;

}  // namespace glintbake::format
