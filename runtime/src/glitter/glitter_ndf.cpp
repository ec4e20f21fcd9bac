// SPDX-License-Identifier: Apache-2.0
#include <glintbake/format/kinds/glitter.h>
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/glitter_ndf.h>
#include "../format_status.h"
#include "../query_args.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::runtime {

RuntimeStatus GlitterNdf::open(const char* path) {
  if (!path) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (format::ContainerStatus st = reader.open(path); st != format::ContainerStatus::kOk) return fromFormatStatus(st);
  return load(reader);
}

RuntimeStatus GlitterNdf::openMemory(const void* data, size_t size) {
  if (!data) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (format::ContainerStatus st = reader.openMemory(data, size); st != format::ContainerStatus::kOk)
    return fromFormatStatus(st);
  return load(reader);
}

RuntimeStatus GlitterNdf::load(const format::Reader& reader) {
  open_ = false;
  table_.reset();
  if (reader.kind() == format::AssetKind::kPartial) return RuntimeStatus::kPartialBake;
  if (reader.kind() != format::AssetKind::kGlitter) return RuntimeStatus::kWrongKind;
  // The layout rule glintinfo validate applies too (6007): one record and one table.
  size_t infos = 0, tables = 0;
  for (const format::SectionInfo& s : reader.sections()) {
    infos += s.type == format::kSectionGlitterInfo;
    tables += s.type == format::kSectionGlitterIntegrals;
  }
  if (format::checkGlitterLayout(infos, tables)) return RuntimeStatus::kInvalidAsset;
  format::GlitterRecord rec;
  if (RuntimeStatus s = readSectionExact(reader, format::kSectionGlitterInfo, &rec, sizeof rec);
      s != RuntimeStatus::kOk)
    return s;
  if (rec.magic == format::GlitterRecord().magic && rec.version > 1) return RuntimeStatus::kUnsupportedVersion;
  if (format::checkGlitterRecord(rec)) return RuntimeStatus::kInvalidAsset;
  std::unique_ptr<format::GlitterIntegral[]> table(new (std::nothrow) format::GlitterIntegral[rec.integral_count]);
  if (!table) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus s = readSectionExact(reader, format::kSectionGlitterIntegrals, table.get(),
                                         size_t(rec.integral_count) * sizeof(format::GlitterIntegral));
      s != RuntimeStatus::kOk)
    return s;
  if (format::checkGlitterIntegrals(table.get(), rec.integral_count)) return RuntimeStatus::kInvalidAsset;
  record_ = rec;
  table_ = std::move(table);
  surface_.distribution = format::GlitterDistribution(rec.distribution);
  surface_.alpha = rec.alpha;
  surface_.particles = rec.particles;
  surface_.seed = rec.seed;
  surface_.max_depth = int(rec.max_depth);
  surface_.integrals = table_.get();
  surface_.integral_count = rec.integral_count;
  open_ = true;
  return RuntimeStatus::kOk;
}

FootprintRange GlitterNdf::footprintRange() const {
  FootprintRange r;
  if (open_) r.exact_max_sigma = 4.0 * std::max(record_.map_width, record_.map_height);
  return r;
}

MapSize GlitterNdf::mapSize() const {
  return open_ ? MapSize{int(record_.map_width), int(record_.map_height)} : MapSize{};
}

bool GlitterNdf::validFootprint(const Footprint& f) const {
  return open_ && std::isfinite(f.x) && std::isfinite(f.y) && std::isfinite(f.sigma) && f.sigma >= 0.0;
}

format::GlitterGaussian GlitterNdf::gaussian(const Footprint& f) const {
  const double w = record_.map_width, h = record_.map_height;
  const double sigma = std::clamp(f.sigma, 1e-4, 4.0 * std::max(w, h));
  format::GlitterGaussian g;
  g.u = f.x / w;
  g.v = f.y / h;
  g.u -= std::floor(g.u);
  g.v -= std::floor(g.v);
  g.sigma_u = std::min(sigma / w, 4.0);
  g.sigma_v = std::min(sigma / h, 4.0);
  return g;
}

// Weighted facets within gamma of h(s) and of its mirror image (when the cone crosses the horizon).
double GlitterNdf::coneWeight(const format::GlitterGaussian& g, const SPoint& s) const {
  const double hz = std::sqrt(std::max(0.0, 1.0 - s.x * s.x - s.y * s.y));
  const format::GlitterTreeShape sh = shape();
  double w = format::glitterWeightedCount(surface_, sh, g,
                                          format::GlitterDirRegion::cone({s.x, s.y, hz}, record_.gamma), nullptr);
  if (hz < std::sin(record_.gamma))
    w += format::glitterWeightedCount(surface_, sh, g, format::GlitterDirRegion::cone({s.x, s.y, -hz}, record_.gamma),
                                      nullptr);
  return w;
}

RuntimeStatus GlitterNdf::eval(const Footprint& footprint, const SPoint& s, double* value) const {
  if (!validFootprint(footprint) || !finitePoint(s) || !value) return RuntimeStatus::kInvalidArgument;
  const double r2 = s.x * s.x + s.y * s.y;
  if (!(r2 < 1.0)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  const double cone = 2.0 * kPi * (1.0 - std::cos(record_.gamma));
  *value = coneWeight(gaussian(footprint), s) / (double(record_.particles) * cone * std::sqrt(1.0 - r2));
  return RuntimeStatus::kOk;
}

RuntimeStatus GlitterNdf::mass(const Footprint& footprint, double* value) const {
  if (!validFootprint(footprint) || !value) return RuntimeStatus::kInvalidArgument;
  *value =
      format::glitterWeightedCount(surface_, shape(), gaussian(footprint), format::GlitterDirRegion::all(), nullptr) /
      double(record_.particles);
  return RuntimeStatus::kOk;
}

RuntimeStatus GlitterNdf::pdf(const Footprint& footprint, const SPoint& s, double* value) const {
  if (!validFootprint(footprint) || !finitePoint(s) || !value) return RuntimeStatus::kInvalidArgument;
  double m = 0.0, e = 0.0;
  mass(footprint, &m);
  if (!(m > 0.0)) {
    *value = 0.0;
    return RuntimeStatus::kOk;
  }
  eval(footprint, s, &e);
  *value = e / m;
  return RuntimeStatus::kOk;
}

RuntimeStatus GlitterNdf::sample(const Footprint& footprint, double u1, double u2, NdfSample* out) const {
  if (!validFootprint(footprint) || !out || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  format::GlitterVec3 n;
  double total = 0.0;
  if (!format::glitterSampleFacet(surface_, shape(), gaussian(footprint), u1, &n, &total, nullptr))
    return RuntimeStatus::kInvalidArgument;
  // A direction uniform in the facet's cone: cos theta uniform in [cos gamma, 1], phi from a hash
  // of both inputs (u1 is spent on the facet).
  uint64_t bits1, bits2;
  std::memcpy(&bits1, &u1, 8);
  std::memcpy(&bits2, &u2, 8);
  const double phi = 2.0 * kPi * format::glitterUniform(format::glitterMix(bits1 ^ format::glitterMix(bits2)), 0);
  const double ct = 1.0 - u2 * (1.0 - std::cos(record_.gamma));
  const format::GlitterVec3 h = format::glitterConeDirection(n, ct, phi);
  // The mirror image of a direction below the horizon has the same s.
  SPoint s{h.x, h.y};
  if (!(s.x * s.x + s.y * s.y < 1.0)) return RuntimeStatus::kInvalidArgument;  // on the horizon itself
  // pdf(): the same eval over the same mass (total is the mass traversal's own sum).
  double e = 0.0;
  eval(footprint, s, &e);
  const double p = e / (total / double(record_.particles));
  if (!(p > 0.0)) return RuntimeStatus::kInvalidArgument;
  out->s = s;
  out->pdf = p;
  return RuntimeStatus::kOk;
}

RuntimeStatus GlitterNdf::average(const Footprint& footprint, const SRect& rect, double* value) const {
  if (!validFootprint(footprint) || !value || !(rect.x0 < rect.x1 && rect.y0 < rect.y1) ||
      !std::isfinite(rect.x0 + rect.x1 + rect.y0 + rect.y1))
    return RuntimeStatus::kInvalidArgument;
  const double w =
      format::glitterWeightedCount(surface_, shape(), gaussian(footprint),
                                   format::GlitterDirRegion::rect(rect.x0, rect.y0, rect.x1, rect.y1), nullptr);
  *value = w / (double(record_.particles) * (rect.x1 - rect.x0) * (rect.y1 - rect.y0));
  return RuntimeStatus::kOk;
}

RuntimeStatus GlitterNdf::image(const Footprint& footprint, float* out, size_t out_count) const {
  const size_t res = size_t(resolution());
  if (!validFootprint(footprint) || !out || out_count < res * res) return RuntimeStatus::kInvalidArgument;
  for (size_t i = 0; i < res * res; ++i) out[i] = 0.0f;
  format::glitterBinnedWeights(surface_, shape(), gaussian(footprint), int(res), out, nullptr);
  const double bin = 2.0 / double(res);
  const float scale = float(1.0 / (double(record_.particles) * bin * bin));
  for (size_t i = 0; i < res * res; ++i) out[i] *= scale;
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
