// SPDX-License-Identifier: Apache-2.0
// The shared surface of pyramid-shaped NDF assets: opening, level records, footprint range and
// map geometry, and the argument checks of every query (pyramid_ndf.h).
#include <glintbake/runtime/pyramid_ndf.h>

#include <glintbake/format/kinds/ndf_pyramid_blend.h>

#include "format_status.h"
#include "pyramid_blend.h"

#include <cmath>

namespace glintbake::runtime {
RuntimeStatus PyramidNdf::load(const format::Reader& reader) {
  reset();
  if (reader.kind() == format::AssetKind::kPartial) return RuntimeStatus::kPartialBake;
  if (reader.kind() != kind()) return RuntimeStatus::kWrongKind;
  const RuntimeStatus status = loadKind(reader);
  if (status != RuntimeStatus::kOk) reset();
  return status;
}

RuntimeStatus PyramidNdf::open(const char* path) {
  reset();
  if (!path) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (RuntimeStatus s = fromFormatStatus(reader.open(path)); s != RuntimeStatus::kOk) return s;
  return load(reader);
}

RuntimeStatus PyramidNdf::openMemory(const void* data, size_t size) {
  reset();
  if (!data) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (RuntimeStatus s = fromFormatStatus(reader.openMemory(data, size)); s != RuntimeStatus::kOk) return s;
  return load(reader);
}

int PyramidNdf::levelCount() const {
  int count = 0;
  return levelRecords(&count) ? count : 0;
}

const NdfLevelRecord* PyramidNdf::level(int l) const {
  int count = 0;
  const NdfLevelRecord* records = levelRecords(&count);
  return records && l >= 0 && l < count ? &records[l] : nullptr;
}

int PyramidNdf::resolution() const {
  const NdfLevelRecord* first = level(0);
  return first ? int(first->ndf_res) : 0;
}

FootprintRange PyramidNdf::footprintRange() const {
  FootprintRange range;
  const int count = levelCount();
  if (count == 0) return range;
  const format::NdfPyramidBlend* b = blender();
  range.pyramid_min_sigma = level(b ? b->firstLevel() : 0)->sigma_texels;
  range.pyramid_max_sigma = level(count - 1)->sigma_texels;
  return range;
}

void PyramidNdf::answerFromSigma(double sigma) {
  if (format::NdfPyramidBlend* b = blender()) b->answerFromSigma(sigma);
}

void PyramidNdf::holdEdges() {
  if (format::NdfPyramidBlend* b = blender()) b->holdEdges();
}

MapSize PyramidNdf::mapSize() const {
  const NdfLevelRecord* first = level(0);
  return first ? MapSize{int(first->map_width), int(first->map_height)} : MapSize{};
}

MapWrap PyramidNdf::wrap() const {
  const NdfLevelRecord* first = level(0);
  return first && first->wrap == 1 ? MapWrap::kClamp : MapWrap::kRepeat;
}

RuntimeStatus PyramidNdf::eval(const Footprint& footprint, const SPoint& s, double* value) const {
  if (!loaded() || !value || !validFootprint(footprint) || !finitePoint(s)) return RuntimeStatus::kInvalidArgument;
  return evalChecked(footprint, s, value);
}

RuntimeStatus PyramidNdf::average(const Footprint& footprint, const SRect& rect, double* value) const {
  if (!loaded() || !value || !validFootprint(footprint) || !validRect(rect)) return RuntimeStatus::kInvalidArgument;
  return averageChecked(footprint, rect, value);
}

RuntimeStatus PyramidNdf::sample(const Footprint& footprint, double u1, double u2, NdfSample* out) const {
  if (!loaded() || !out || !validFootprint(footprint) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  return sampleChecked(footprint, u1, u2, out);
}

RuntimeStatus PyramidNdf::pdf(const Footprint& footprint, const SPoint& s, double* value) const {
  if (!loaded() || !value || !validFootprint(footprint) || !finitePoint(s)) return RuntimeStatus::kInvalidArgument;
  return pdfChecked(footprint, s, value);
}

RuntimeStatus PyramidNdf::mass(const Footprint& footprint, double* value) const {
  if (!loaded() || !value || !validFootprint(footprint)) return RuntimeStatus::kInvalidArgument;
  return massChecked(footprint, value);
}

RuntimeStatus PyramidNdf::image(const Footprint& footprint, float* out, size_t out_count) const {
  if (!loaded()) return RuntimeStatus::kInvalidArgument;
  const size_t n = size_t(resolution()) * size_t(resolution());
  if (!out || out_count < n || !validFootprint(footprint)) return RuntimeStatus::kInvalidArgument;
  return imageChecked(footprint, out);
}

}  // namespace glintbake::runtime
