// SPDX-License-Identifier: Apache-2.0
// Runtime-lite: constant-cost queries on baked glintbake assets. Built without exceptions and
// RTTI; no allocation per query; const queries are thread-safe.
#pragma once

#include <cstdint>

namespace glintbake::runtime {

enum class RuntimeStatus : int32_t {
  kOk = 0,
  kIoError = 1,
  kInvalidAsset = 2,        // the container or its sections are malformed
  kWrongKind = 3,           // the container holds another asset kind
  kUnsupportedVersion = 4,  // newer container major version
  kInvalidArgument = 5,
  kOutOfMemory = 6,
  kPartialBake = 7,  // a partial container (one shard of a sharded bake): merge the shards first
};

// The former name of RuntimeStatus, kept for one minor version.
using Status [[deprecated("use glintbake::runtime::RuntimeStatus")]] = RuntimeStatus;

// Stable, human-readable name of a status. Never returns null.
const char* statusString(RuntimeStatus status);

// A Gaussian pixel footprint on the surface: centre (x, y) and standard deviation sigma, all in
// texels of the source normal map (texel centres at +0.5, y grows downwards; formats/SPEC.md).
struct Footprint {
  double x = 0.0;
  double y = 0.0;
  double sigma = 1.0;
};

// A point of the projected hemisphere (s-plane): s = (h_x, h_y) of a unit direction in the tangent
// frame, |s| <= 1. NDF values are densities per unit s-plane area.
struct SPoint {
  double x = 0.0;
  double y = 0.0;
};

// A rectangle of the s-plane [x0, x1] x [y0, y1] (x0 < x1, y0 < y1).
struct SRect {
  double x0 = -1.0, y0 = -1.0, x1 = 1.0, y1 = 1.0;
};

// Result of importance sampling the P-NDF: the sampled point and its density (== eval at s).
struct NdfSample {
  SPoint s;
  double pdf = 0.0;
};

}  // namespace glintbake::runtime
