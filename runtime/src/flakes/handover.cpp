// The flakes section loader and the flakes-to-pyramid hand-over (see handover.h).
#include "handover.h"

#include "../format_status.h"
#include "../heap_array.h"
#include "../pyramid_blend.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::runtime {
Status loadFlakes(const format::Reader& reader, int section, int resolution, FlakePaths* paths) {
  const format::SectionInfo& info = reader.sections()[size_t(section)];
  if (info.raw_size < sizeof(format::FlakesRecord)) return Status::kInvalidAsset;
  // Sections decode whole: refuse sizes no valid record can have before decoding, and check the
  // record against the actual size after.
  format::FlakesRecord rec;
  if (info.raw_size > uint64_t(sizeof(rec)) + uint64_t(format::kMaxFlakesCount) * 8u) return Status::kInvalidAsset;
  Array<uint8_t> section_bytes;
  if (!section_bytes.allocate(size_t(info.raw_size))) return Status::kOutOfMemory;
  if (Status s = fromFormatStatus(reader.readSectionInto(size_t(section), section_bytes.data, section_bytes.size));
      s != Status::kOk)
    return s;
  std::memcpy(&rec, section_bytes.data, sizeof(rec));
  if (format::checkFlakesRecord(rec, info.raw_size) != nullptr) return Status::kInvalidAsset;
  const float* normals = reinterpret_cast<const float*>(section_bytes.data + sizeof(rec));
  const InterleavedTexels texels(int(rec.map_width), int(rec.map_height), rec.wrap == 0, normals, 2);
  FlakePaths p;
  p.flakes.reset(new (std::nothrow) FlakeNdf());
  if (!p.flakes) return Status::kOutOfMemory;
  Status built = p.flakes->build(texels, int(rec.rate), rec.sigma_r, resolution);
  if (built == Status::kOk && format::hasLobes(rec)) {
    p.lobes.reset(new (std::nothrow) LobeNdf());
    built = p.lobes ? p.lobes->build(texels, int(rec.rate), rec.sigma_r, int(rec.lobes_per_tile), resolution)
                    : Status::kOutOfMemory;
  }
  if (built == Status::kInvalidArgument) return Status::kInvalidAsset;  // non-finite normals
  if (built != Status::kOk) return built;
  p.record = rec;
  *paths = std::move(p);
  return Status::kOk;
}

HandoverNdf::HandoverNdf(FlakePaths paths, std::unique_ptr<NdfSource> pyramid)
    : paths_(std::move(paths)), pyramid_(std::move(pyramid)) {
  const format::FlakesRecord& r = paths_.record;
  flakes_up_to_ = r.flakes_up_to;
  pyramid_from_ = r.pyramid_from;
  lobes_from_ = lobes_up_to_ = 0.0;
  if (paths_.lobes) {
    // The lobes answer up to the record's bound, and never beyond their own window limit.
    lobes_from_ = r.flakes_up_to * format::kLobesBand;
    lobes_up_to_ = std::max(lobes_from_, std::min(r.lobes_up_to, paths_.lobes->footprintRange().clustered_max_sigma));
    pyramid_from_ = std::max(pyramid_from_, lobes_up_to_);
  }
}

FootprintRange HandoverNdf::footprintRange() const {
  FootprintRange r = pyramid_->footprintRange();
  r.exact_max_sigma = flakes_up_to_;
  r.handover_max_sigma = pyramid_from_;
  r.clustered_min_sigma = lobes_from_;
  r.clustered_max_sigma = lobes_up_to_;
  return r;
}

HandoverNdf::Mix HandoverNdf::mixFor(double sigma) const {
  auto band = [](double s, double lo, double hi) { return hi > lo ? std::log(s / lo) / std::log(hi / lo) : 1.0; };
  const AccumulatingNdfSource* flakes = paths_.flakes.get();
  if (sigma <= flakes_up_to_) return {flakes, nullptr, 0.0};
  if (sigma >= pyramid_from_) return {flakes, pyramid_.get(), 1.0};
  if (!paths_.lobes) return {flakes, pyramid_.get(), band(sigma, flakes_up_to_, pyramid_from_)};
  const AccumulatingNdfSource* lobes = paths_.lobes.get();
  if (sigma < lobes_from_) return {flakes, lobes, band(sigma, flakes_up_to_, lobes_from_)};
  if (sigma <= lobes_up_to_) return {lobes, nullptr, 0.0};
  return {lobes, pyramid_.get(), band(sigma, lobes_up_to_, pyramid_from_)};
}

// (1 - t) query(lower) + t query(upper), querying only the paths with a non-zero weight.
template <typename Query>
Status HandoverNdf::blend(const Footprint& fp, double* value, Query&& query) const {
  if (!value || !validFootprint(fp)) return Status::kInvalidArgument;
  const Mix mix = mixFor(fp.sigma);
  double a = 0.0, b = 0.0;
  if (mix.t < 1.0) {
    if (Status s = query(*mix.lower, &a); s != Status::kOk) return s;
  }
  if (mix.t > 0.0) {
    if (Status s = query(*mix.upper, &b); s != Status::kOk) return s;
  }
  *value = mix.t <= 0.0 ? a : (mix.t >= 1.0 ? b : (1.0 - mix.t) * a + mix.t * b);
  return Status::kOk;
}

Status HandoverNdf::eval(const Footprint& fp, const SPoint& s, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.eval(fp, s, v); });
}

Status HandoverNdf::average(const Footprint& fp, const SRect& rect, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.average(fp, rect, v); });
}

Status HandoverNdf::mass(const Footprint& fp, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.mass(fp, v); });
}

Status HandoverNdf::pdf(const Footprint& fp, const SPoint& s, double* value) const {
  if (!value) return Status::kInvalidArgument;
  double e = 0.0, m = 0.0;
  if (Status st = eval(fp, s, &e); st != Status::kOk) return st;
  if (Status st = mass(fp, &m); st != Status::kOk) return st;
  *value = m > 0.0 ? e / m : 0.0;
  return Status::kOk;
}

Status HandoverNdf::sample(const Footprint& fp, double u1, double u2, NdfSample* out) const {
  if (!out || !validFootprint(fp) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return Status::kInvalidArgument;
  const Mix mix = mixFor(fp.sigma);
  NdfSample picked;
  if (mix.t <= 0.0 || mix.t >= 1.0) {
    const NdfSource& src = mix.t <= 0.0 ? static_cast<const NdfSource&>(*mix.lower) : *mix.upper;
    if (Status s = src.sample(fp, u1, u2, &picked); s != Status::kOk) return s;
  } else {
    // A path in proportion to its weighted mass, u1 rescaled within the choice.
    double ma = 0.0, mb = 0.0;
    if (Status s = mix.lower->mass(fp, &ma); s != Status::kOk) return s;
    if (Status s = mix.upper->mass(fp, &mb); s != Status::kOk) return s;
    const double wa = (1.0 - mix.t) * ma, wb = mix.t * mb;
    if (!(wa + wb > 0.0)) return Status::kInvalidArgument;
    const double x = u1 * (wa + wb);
    const bool first = x < wa;
    const double v = first ? x / wa : (x - wa) / wb;
    const double u = std::fmin(std::fmax(v, 0.0), 0.99999999999999989);
    const NdfSource& src = first ? static_cast<const NdfSource&>(*mix.lower) : *mix.upper;
    if (Status s = src.sample(fp, u, u2, &picked); s != Status::kOk) return s;
  }
  out->s = picked.s;
  return pdf(fp, picked.s, &out->pdf);
}

Status HandoverNdf::image(const Footprint& fp, float* out, size_t out_count) const {
  const int res = pyramid_->resolution();
  const size_t n = size_t(res) * size_t(res);
  if (!out || out_count < n || !validFootprint(fp)) return Status::kInvalidArgument;
  const Mix mix = mixFor(fp.sigma);
  if (mix.t <= 0.0) return mix.lower->image(fp, out, out_count);
  if (mix.t >= 1.0) return mix.upper->image(fp, out, out_count);
  // The upper path's image scaled in place, then the lower path's lobes added on top.
  if (Status s = mix.upper->image(fp, out, out_count); s != Status::kOk) return s;
  for (size_t i = 0; i < n; ++i) out[i] = float(mix.t * double(out[i]));
  return mix.lower->addImage(fp, 1.0 - mix.t, out, out_count);
}

}  // namespace glintbake::runtime
