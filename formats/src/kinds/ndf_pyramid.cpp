// SPDX-License-Identifier: Apache-2.0
// The ndf-level record check (formats/SPEC.md 10.1).
#include <glintbake/format/kinds/ndf_pyramid.h>

#include <cmath>

namespace glintbake::format {
namespace {

bool finitePositive(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

RecordCheck checkNdfLevelRecord(const NdfLevelRecord& r, uint32_t key, const NdfLevelRecord* below) {
  if (r.magic != NdfLevelRecord().magic) return {RecordStatus::kBadMagic, "bad magic"};
  if (r.version != 1) return {RecordStatus::kUnsupportedVersion, "unsupported version"};
  if (r.level != key) return recordInvalid("key and level field disagree");
  if (r.ndf_res < 2 || r.ndf_res > kMaxNdfResolution) return recordInvalid("NDF resolution out of range");
  if (below && r.ndf_res != below->ndf_res) return recordInvalid("NDF resolution differs from the level below");
  if (r.grid_width < 1 || r.grid_height < 1 || r.grid_width > kMaxNdfGridSide || r.grid_height > kMaxNdfGridSide)
    return recordInvalid("centre grid out of range");
  if (r.region_size < 1 || r.regions_x != (r.grid_width + r.region_size - 1) / r.region_size ||
      r.regions_y != (r.grid_height + r.region_size - 1) / r.region_size)
    return recordInvalid("region layout inconsistent with the grid");
  if (r.wrap > 1) return recordInvalid("unknown wrap mode");
  if (!finitePositive(r.stride_x) || !finitePositive(r.stride_y) || !std::isfinite(r.origin_x) ||
      !std::isfinite(r.origin_y) || !finitePositive(r.sigma_texels) || !std::isfinite(r.sigma_r))
    return recordInvalid("non-finite or non-positive geometry");
  if (below && !(r.sigma_texels > below->sigma_texels))
    return recordInvalid("footprint sigma not larger than the level below");
  return recordOk();
}

}  // namespace glintbake::format
