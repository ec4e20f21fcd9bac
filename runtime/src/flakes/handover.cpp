// The flakes section loader and the flakes-to-pyramid hand-over (see handover.h).
#include "handover.h"

#include "../format_status.h"
#include "../heap_array.h"
#include "../pyramid_blend.h"

#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::runtime {
namespace {}  // namespace

RuntimeStatus loadFlakes(const format::Reader& reader, int section, int resolution, std::unique_ptr<FlakeNdf>* flakes,
                         format::FlakesRecord* record) {
  const format::SectionInfo& info = reader.sections()[size_t(section)];
  if (info.raw_size < sizeof(format::FlakesRecord)) return RuntimeStatus::kInvalidAsset;
  // Sections decode whole: refuse sizes no valid record can have before decoding, and check the
  // record against the actual size after.
  format::FlakesRecord rec;
  if (info.raw_size > uint64_t(sizeof(rec)) + uint64_t(format::kMaxFlakesCount) * 8u)
    return RuntimeStatus::kInvalidAsset;
  Array<uint8_t> section_bytes;
  if (!section_bytes.allocate(size_t(info.raw_size))) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus s =
          fromFormatStatus(reader.readSectionInto(size_t(section), section_bytes.data, section_bytes.size));
      s != RuntimeStatus::kOk)
    return s;
  std::memcpy(&rec, section_bytes.data, sizeof(rec));
  if (format::checkFlakesRecord(rec, info.raw_size) != nullptr) return RuntimeStatus::kInvalidAsset;
  const float* normals = reinterpret_cast<const float*>(section_bytes.data + sizeof(rec));
  const InterleavedTexels texels(int(rec.map_width), int(rec.map_height), rec.wrap == 0, normals, 2);
  std::unique_ptr<FlakeNdf> f(new (std::nothrow) FlakeNdf());
  if (!f) return RuntimeStatus::kOutOfMemory;
  const RuntimeStatus built = f->build(texels, int(rec.rate), rec.sigma_r, resolution);
  if (built == RuntimeStatus::kInvalidArgument) return RuntimeStatus::kInvalidAsset;  // non-finite normals
  if (built != RuntimeStatus::kOk) return built;
  *flakes = std::move(f);
  *record = rec;
  return RuntimeStatus::kOk;
}

HandoverNdf::HandoverNdf(std::unique_ptr<FlakeNdf> flakes, std::unique_ptr<NdfSource> pyramid, double flakes_up_to,
                         double pyramid_from)
    : flakes_(std::move(flakes)),
      pyramid_(std::move(pyramid)),
      flakes_up_to_(flakes_up_to),
      pyramid_from_(pyramid_from),
      inv_log_band_(pyramid_from > flakes_up_to ? 1.0 / std::log(pyramid_from / flakes_up_to) : 0.0) {}

FootprintRange HandoverNdf::footprintRange() const {
  FootprintRange r = pyramid_->footprintRange();
  r.exact_max_sigma = flakes_up_to_;
  r.handover_max_sigma = pyramid_from_;
  return r;
}

double HandoverNdf::pyramidWeight(double sigma) const {
  if (sigma <= flakes_up_to_) return 0.0;
  if (sigma >= pyramid_from_) return 1.0;
  return std::log(sigma / flakes_up_to_) * inv_log_band_;
}

// (1 - t) query(flakes) + t query(pyramid), querying only the paths with a non-zero weight.
template <typename Query>
RuntimeStatus HandoverNdf::blend(const Footprint& fp, double* value, Query&& query) const {
  if (!value || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  const double t = pyramidWeight(fp.sigma);
  double a = 0.0, b = 0.0;
  if (t < 1.0) {
    if (RuntimeStatus s = query(*flakes_, &a); s != RuntimeStatus::kOk) return s;
  }
  if (t > 0.0) {
    if (RuntimeStatus s = query(*pyramid_, &b); s != RuntimeStatus::kOk) return s;
  }
  *value = t <= 0.0 ? a : (t >= 1.0 ? b : (1.0 - t) * a + t * b);
  return RuntimeStatus::kOk;
}

RuntimeStatus HandoverNdf::eval(const Footprint& fp, const SPoint& s, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.eval(fp, s, v); });
}

RuntimeStatus HandoverNdf::average(const Footprint& fp, const SRect& rect, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.average(fp, rect, v); });
}

RuntimeStatus HandoverNdf::mass(const Footprint& fp, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.mass(fp, v); });
}

RuntimeStatus HandoverNdf::pdf(const Footprint& fp, const SPoint& s, double* value) const {
  if (!value) return RuntimeStatus::kInvalidArgument;
  double e = 0.0, m = 0.0;
  if (RuntimeStatus st = eval(fp, s, &e); st != RuntimeStatus::kOk) return st;
  if (RuntimeStatus st = mass(fp, &m); st != RuntimeStatus::kOk) return st;
  *value = m > 0.0 ? e / m : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus HandoverNdf::sample(const Footprint& fp, double u1, double u2, NdfSample* out) const {
  if (!out || !validFootprint(fp) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  const double t = pyramidWeight(fp.sigma);
  NdfSample picked;
  if (t <= 0.0 || t >= 1.0) {
    if (RuntimeStatus s = (t <= 0.0 ? static_cast<const NdfSource&>(*flakes_) : *pyramid_).sample(fp, u1, u2, &picked);
        s != RuntimeStatus::kOk)
      return s;
  } else {
    // A path in proportion to its weighted mass, u1 rescaled within the choice.
    double ma = 0.0, mb = 0.0;
    if (RuntimeStatus s = flakes_->mass(fp, &ma); s != RuntimeStatus::kOk) return s;
    if (RuntimeStatus s = pyramid_->mass(fp, &mb); s != RuntimeStatus::kOk) return s;
    const double wa = (1.0 - t) * ma, wb = t * mb;
    if (!(wa + wb > 0.0)) return RuntimeStatus::kInvalidArgument;
    const double x = u1 * (wa + wb);
    const bool first = x < wa;
    const double v = first ? x / wa : (x - wa) / wb;
    const double u = std::fmin(std::fmax(v, 0.0), 0.99999999999999989);
    const NdfSource& src = first ? static_cast<const NdfSource&>(*flakes_) : *pyramid_;
    if (RuntimeStatus s = src.sample(fp, u, u2, &picked); s != RuntimeStatus::kOk) return s;
  }
  out->s = picked.s;
  return pdf(fp, picked.s, &out->pdf);
}

RuntimeStatus HandoverNdf::image(const Footprint& fp, float* out, size_t out_count) const {
  const int res = pyramid_->resolution();
  const size_t n = size_t(res) * size_t(res);
  if (!out || out_count < n || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  const double t = pyramidWeight(fp.sigma);
  if (t <= 0.0) return flakes_->image(fp, out, out_count);
  if (t >= 1.0) return pyramid_->image(fp, out, out_count);
  // The pyramid's image scaled in place, then the flakes' lobes added on top.
  if (RuntimeStatus s = pyramid_->image(fp, out, out_count); s != RuntimeStatus::kOk) return s;
  for (size_t i = 0; i < n; ++i) out[i] = float(t * double(out[i]));
  return flakes_->addImage(fp, 1.0 - t, out, out_count);
}

}  // namespace glintbake::runtime
