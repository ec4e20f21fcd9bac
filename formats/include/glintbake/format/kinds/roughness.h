// SPDX-License-Identifier: Apache-2.0
// Sections of roughness assets (formats/SPEC.md section 10.3), written by libbake's roughness mip
// writer (ltcfit roughness): one image section of type 64 per mip level, key = level, W_l x H_l x 1
// (W_l = ceil(W / 2^l), down to 1 x 1).
#pragma once

#include <cstdint>

namespace glintbake::format {

constexpr uint32_t kRoughnessChannels = 1;
}  // namespace glintbake::format
