// SPDX-License-Identifier: Apache-2.0
// Checks of the flakes section record (see kinds/flakes.h).
#include <glintbake/format/kinds/flakes.h>

#include <cmath>
#include <cstring>

namespace glintbake::format {

uint64_t flakesSectionSize(const FlakesRecord& r) {
  if (r.map_width < 1 || r.map_height < 1 || r.map_width > kMaxFlakesMapSide || r.map_height > kMaxFlakesMapSide)
    return 0;
  return sizeof(FlakesRecord) + uint64_t(r.map_width) * uint64_t(r.map_height) * 8u +
         (r.version >= 3 ? sizeof(FlakesTrailer) : 0u);
}

const char* checkFlakesTrailer(const FlakesTrailer& t) {
  if (t.tile_ratio_milli < kMinFlakesTileRatioMilli || t.tile_ratio_milli > kMaxFlakesTileRatioMilli)
    return "flakes trailer: tile_ratio out of range";
  if (t.reserved != 0) return "flakes trailer: reserved is not 0";
  return nullptr;
}

bool flakesTileRatio(const FlakesRecord& r, const uint8_t* section, uint64_t raw_size, uint32_t* milli) {
  *milli = kDefaultFlakesTileRatioMilli;
  if (r.version < 3) return true;
  if (raw_size < sizeof(FlakesRecord) + sizeof(FlakesTrailer)) return false;
  FlakesTrailer t;
  std::memcpy(&t, section + (raw_size - sizeof(t)), sizeof(t));
  if (checkFlakesTrailer(t)) return false;
  *milli = t.tile_ratio_milli;
  return true;
}

const char* checkFlakesRecord(const FlakesRecord& r, uint64_t section_raw_size) {
  if (r.magic != FlakesRecord().magic) return "flakes record: bad magic";
  if (r.version < 1 || r.version > 3) return "flakes record: unsupported version";
  if (flakesSectionSize(r) == 0) return "flakes record: map size out of range";
  if (r.wrap > 1) return "flakes record: wrap is neither repeat nor clamp";
  if (r.rate < 1 || r.rate > kMaxFlakesRate) return "flakes record: rate out of range";
  if (uint64_t(r.map_width) * r.map_height * r.rate * r.rate > kMaxFlakesCount) return "flakes record: too many flakes";
  if (r.precision != 0) return "flakes record: unknown precision";
  if (!(std::isfinite(r.sigma_r) && r.sigma_r > 0.0 && r.sigma_r <= 1.0)) return "flakes record: sigma_r out of range";
  if (!(std::isfinite(r.flakes_up_to) && r.flakes_up_to >= 0.0 && r.flakes_up_to <= 1e6))
    return "flakes record: flakes_up_to out of range";
  if (!(std::isfinite(r.pyramid_from) && r.pyramid_from >= r.flakes_up_to && r.pyramid_from <= 1e6))
    return "flakes record: pyramid_from below flakes_up_to";
  if (r.version >= 2) {
    if (r.lobes_per_tile > kMaxLobesPerTile) return "flakes record: lobes_per_tile out of range";
    if (r.lobes_per_tile > 0 && !(std::isfinite(r.lobes_up_to) && r.lobes_up_to >= r.flakes_up_to * kLobesBand &&
                                  r.lobes_up_to <= r.pyramid_from))
      return "flakes record: lobes_up_to outside [flakes_up_to x sqrt(2), pyramid_from]";
    if (r.lobes_per_tile == 0 && r.lobes_up_to != 0.0) return "flakes record: lobes_up_to without lobes";
  }
  if (section_raw_size != flakesSectionSize(r)) return "flakes record: section size does not match the map size";
  return nullptr;
}

}  // namespace glintbake::format
