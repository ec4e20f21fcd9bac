// SPDX-License-Identifier: Apache-2.0
// Writing the flakes section of NDF assets (see flakes_section.h).
#include <glintbake/bake/ndf/flakes_section.h>

#include <glintbake/bake/ndf/pyramid_builder.h>

#include <glintbake/format/kinds/flakes.h>
#include <glintbake/runtime/flake_ndf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace glintbake::bake::ndf {

namespace {
constexpr double kFlakesUpTo = 4.0;  // texels: the flakes answer at least this far
constexpr double kHalfOctave = 1.4142135623730951;
constexpr double kLobesUnbounded = 1e6;  // the record's largest footprint bound
}  // namespace

FlakesHandover capAtFlatFootprint(const FlakesHandover& handover, int map_width, int map_height, bool repeat) {
  FlakesHandover h = handover;
  if (!repeat || h.lobes_per_tile <= 0 || !(h.lobes_up_to < kLobesUnbounded)) return h;
  const double flat = kFlatAxisSigma * double(std::max(map_width, map_height));
  if (!(h.pyramid_from > flat)) return h;
  // Both stay within the record's bounds: lobes_from <= lobes_up_to <= pyramid_from.
  const double lobes_from = h.flakes_up_to * format::kLobesBand;
  h.pyramid_from = std::max(flat, lobes_from);
  h.lobes_up_to = std::max(lobes_from, std::min(h.lobes_up_to, h.pyramid_from / kHalfOctave));
  return h;
}

FlakesHandover fitHandoverToMap(const FlakesHandover& handover, int map_width, int map_height, bool repeat, int rate) {
  if (repeat) return capAtFlatFootprint(handover, map_width, map_height, true);
  if (map_width < 1 || map_height < 1 || rate < 1) return handover;
  const uint64_t flakes = uint64_t(map_width) * uint64_t(map_height) * uint64_t(rate) * uint64_t(rate);
  const double flat = kClampedFlatSigma * double(std::max(map_width, map_height));
  // The flakes path's window at F: 2 kFlakeWindowSigmas sqrt(F^2 + sigma_h^2) flakes across
  // (sigma_h < 1 texel), plus the two rounded ends.
  const double window = 2.0 * runtime::kFlakeWindowSigmas * std::sqrt(flat * flat + 1.0) * double(rate) + 2.0;
  if (flakes > kSmallClampedMapFlakes || !(window < double(runtime::kMaxFlakeWindow)) ||
      !(handover.flakes_up_to < flat))
    return handover;
  FlakesHandover h;
  h.flakes_up_to = flat;
  h.lobes_per_tile = 0;
  h.lobes_up_to = 0.0;
  h.pyramid_from = flat * kHalfOctave;
  return h;
}

FlakesHandover defaultHandover(double sigma0, int lobes_per_tile) {
  FlakesHandover h;
  if (lobes_per_tile <= 0) {
    h.flakes_up_to = std::max(kFlakesUpTo, sigma0);
    h.pyramid_from = h.flakes_up_to * kHalfOctave;
    return h;
  }
  h.flakes_up_to = kFlakesUpTo;
  h.lobes_per_tile = lobes_per_tile;
  h.lobes_up_to = std::max(kFlakesUpTo * format::kLobesBand, sigma0 * kHalfOctave);
  h.pyramid_from = std::max(2.0 * sigma0, h.lobes_up_to);
  return h;
}

FlakesHandover compressedHandover(const double* level_sigmas, const double* level_errors, int levels,
                                  double max_level_error, int lobes_per_tile, const bool* level_exact,
                                  const double* level_variation) {
  if (lobes_per_tile <= 0 || levels <= 0) return defaultHandover(levels > 0 ? level_sigmas[0] : 0.0, lobes_per_tile);
  int first = levels;  // the first level from which every level is faithful
  while (first > 0 && level_errors[first - 1] <= max_level_error) --first;
  FlakesHandover h;
  h.flakes_up_to = kFlakesUpTo;
  h.lobes_per_tile = lobes_per_tile;
  const bool glinty = first < levels && level_variation && level_variation[first] > kGlintyVariation;
  if (first < levels && level_exact && level_exact[first] && !glinty) {
    // An exact level whose images vary little blends closer to the reference from its own sigma up
    // than the lobes above their finest tiles (kGlintyVariation), so the lobes hand over at that
    // sigma; above a glinty one they go on as above a compressed level (below).
    h.lobes_up_to = std::max(kFlakesUpTo * format::kLobesBand, level_sigmas[first]);
    h.pyramid_from = std::max(kHalfOctave * level_sigmas[first], h.lobes_up_to);
    return h;
  }
  if (first == 0) return defaultHandover(level_sigmas[0], lobes_per_tile);
  if (first == levels) {
    h.lobes_up_to = h.pyramid_from = kLobesUnbounded;
  } else {
    // As for an uncompressed pyramid: between the centres of its first level the pyramid blends
    // images, so the lobes answer up to sqrt(2) x its sigma and the pyramid alone from 2 x.
    h.lobes_up_to = std::max(kFlakesUpTo * format::kLobesBand, level_sigmas[first] * kHalfOctave);
    h.pyramid_from = std::max(2.0 * level_sigmas[first], h.lobes_up_to);
  }
  return h;
}

namespace {
// The record's hand-over, fitted to its map as fitHandoverToMap does.
void fitRecord(format::FlakesRecord* rec) {
  FlakesHandover h;
  h.flakes_up_to = rec->flakes_up_to;
  h.lobes_per_tile = int(rec->lobes_per_tile);
  h.lobes_up_to = rec->lobes_up_to;
  h.pyramid_from = rec->pyramid_from;
  h = fitHandoverToMap(h, int(rec->map_width), int(rec->map_height), rec->wrap == 0, int(rec->rate));
  rec->flakes_up_to = h.flakes_up_to;
  rec->lobes_per_tile = uint32_t(std::max(h.lobes_per_tile, 0));
  rec->lobes_up_to = h.lobes_per_tile > 0 ? h.lobes_up_to : 0.0;
  rec->pyramid_from = h.pyramid_from;
}
}  // namespace

Result<std::vector<uint8_t>> flakesSectionBytes(const NormalMap& map, int rate, double sigma_r,
                                                const FlakesHandover& handover) {
  format::FlakesRecord rec;
  rec.map_width = uint32_t(std::max(map.width, 0));
  rec.map_height = uint32_t(std::max(map.height, 0));
  rec.wrap = map.wrap == Wrap::kRepeat ? 0u : 1u;
  rec.rate = uint32_t(std::max(rate, 0));
  rec.sigma_r = sigma_r;
  rec.flakes_up_to = handover.flakes_up_to;
  rec.pyramid_from = handover.pyramid_from;
  rec.lobes_per_tile = uint32_t(std::max(handover.lobes_per_tile, 0));
  rec.lobes_up_to = handover.lobes_per_tile > 0 ? handover.lobes_up_to : 0.0;
  fitRecord(&rec);
  const uint64_t size = format::flakesSectionSize(rec);
  if (const char* why = format::checkFlakesRecord(rec, size)) return makeError(ErrorCode::kBadArgument, why);
  std::vector<uint8_t> section;
  try {
    section.resize(size_t(size));
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory for the flakes section");
  }
  std::memcpy(section.data(), &rec, sizeof(rec));
  float* normals = reinterpret_cast<float*>(section.data() + sizeof(rec));
  const size_t texels = size_t(map.width) * size_t(map.height);
  for (size_t t = 0; t < texels; ++t) {
    normals[t * 2 + 0] = map.normals[t * 3 + 0];
    normals[t * 2 + 1] = map.normals[t * 3 + 1];
  }
  return section;
}

BakeStatus setFlakesHandover(std::vector<uint8_t>& section, const FlakesHandover& handover) {
  format::FlakesRecord rec;
  if (section.size() < sizeof(rec)) return makeError(ErrorCode::kInvalidInput, "the flakes section is truncated");
  std::memcpy(&rec, section.data(), sizeof(rec));
  rec.version = format::FlakesRecord().version;
  rec.flakes_up_to = handover.flakes_up_to;
  rec.pyramid_from = handover.pyramid_from;
  rec.lobes_per_tile = uint32_t(std::max(handover.lobes_per_tile, 0));
  rec.lobes_up_to = handover.lobes_per_tile > 0 ? handover.lobes_up_to : 0.0;
  fitRecord(&rec);
  if (const char* why = format::checkFlakesRecord(rec, section.size())) return makeError(ErrorCode::kInvalidInput, why);
  std::memcpy(section.data(), &rec, sizeof(rec));
  return okStatus();
}

BakeStatus writeFlakesSection(format::Writer& writer, const NormalMap& map, int rate, double sigma_r,
                              const FlakesHandover& handover, uint64_t* bytes) {
  Result<std::vector<uint8_t>> section = flakesSectionBytes(map, rate, sigma_r, handover);
  if (!section) return section.error();
  if (format::ContainerStatus s =
          writer.addSection(format::kSectionFlakes, 0, section.value().data(), section.value().size());
      s != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, std::string("cannot write the flakes section: ") + format::statusString(s));
  if (bytes) *bytes = section.value().size();
  return okStatus();
}

}  // namespace glintbake::bake::ndf
