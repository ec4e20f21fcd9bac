// SPDX-License-Identifier: Apache-2.0
// The flakes section loader and the flakes-to-pyramid hand-over (see handover.h).
#include "handover.h"

#include "../format_status.h"
#include "../heap_array.h"
#include "../pyramid_blend.h"
#include "flake_access.h"
#include "flake_model.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::runtime {
namespace {
// sqrt(2) and a little: a level of exactly lobes_up_to / sqrt(2) still answers despite rounding.
constexpr double kHalfOctaveWithSlack = 1.4142135623730951 * (1.0 + 1e-9);
}  // namespace
RuntimeStatus loadFlakes(const format::Reader& reader, int section, int resolution, FlakePaths* paths) {
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
  uint32_t tile_ratio_milli = 0;
  if (!format::flakesTileRatio(rec, section_bytes.data, info.raw_size, &tile_ratio_milli))
    return RuntimeStatus::kInvalidAsset;
  const float* normals = reinterpret_cast<const float*>(section_bytes.data + sizeof(rec));
  const InterleavedTexels texels(int(rec.map_width), int(rec.map_height), rec.wrap == 0, normals, 2);
  FlakePaths p;
  p.flakes.reset(new (std::nothrow) FlakeNdf());
  if (!p.flakes) return RuntimeStatus::kOutOfMemory;
  RuntimeStatus built = p.flakes->build(texels, int(rec.rate), rec.sigma_r, resolution);
  if (built == RuntimeStatus::kOk && format::hasLobes(rec)) {
    p.lobes.reset(new (std::nothrow) LobeNdf());
    // The lobes answer their finest level from these flakes (FlakePaths destroys the lobes first).
    built = p.lobes ? LobeNdfAccess::build(*p.lobes, texels, int(rec.rate), rec.sigma_r, int(rec.lobes_per_tile),
                                           resolution, p.flakes.get())
                    : RuntimeStatus::kOutOfMemory;
    if (built == RuntimeStatus::kOk) built = p.lobes->setTileRatio(tile_ratio_milli / 1000.0);
  }
  if (built == RuntimeStatus::kInvalidArgument) return RuntimeStatus::kInvalidAsset;  // non-finite normals
  if (built != RuntimeStatus::kOk) return built;
  p.record = rec;
  *paths = std::move(p);
  return RuntimeStatus::kOk;
}

double BandFlakes::norm() {
  static const double scale = 1.0 / (1.0 - std::exp(-kBandFlakeWindow * kBandFlakeWindow / 2.0));
  return scale;
}

namespace {
// *value = norm() x what `query` writes to its argument (a windowed FlakeNdfAccess sum).
template <typename Query>
RuntimeStatus scaledByNorm(double* value, Query&& query) {
  if (!value) return RuntimeStatus::kInvalidArgument;
  double v = 0.0;
  if (RuntimeStatus st = query(&v); st != RuntimeStatus::kOk) return st;
  *value = v * BandFlakes::norm();
  return RuntimeStatus::kOk;
}
}  // namespace

RuntimeStatus BandFlakes::eval(const Footprint& fp, const SPoint& s, double* value) const {
  return scaledByNorm(value,
                      [&](double* v) { return FlakeNdfAccess::windowedEval(*flakes_, fp, s, kBandFlakeWindow, v); });
}

RuntimeStatus BandFlakes::average(const Footprint& fp, const SRect& rect, double* value) const {
  return scaledByNorm(
      value, [&](double* v) { return FlakeNdfAccess::windowedAverage(*flakes_, fp, rect, kBandFlakeWindow, v); });
}

RuntimeStatus BandFlakes::mass(const Footprint& fp, double* value) const {
  return scaledByNorm(value,
                      [&](double* v) { return FlakeNdfAccess::windowedMass(*flakes_, fp, kBandFlakeWindow, v); });
}

RuntimeStatus BandFlakes::pdf(const Footprint& fp, const SPoint& s, double* value) const {
  if (!value) return RuntimeStatus::kInvalidArgument;
  double e = 0.0, m = 0.0;
  if (RuntimeStatus st = eval(fp, s, &e); st != RuntimeStatus::kOk) return st;
  if (RuntimeStatus st = mass(fp, &m); st != RuntimeStatus::kOk) return st;
  *value = m > 0.0 ? e / m : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus BandFlakes::addImage(const Footprint& fp, double weight, float* out, size_t out_count) const {
  if (!std::isfinite(weight)) return RuntimeStatus::kInvalidArgument;
  return FlakeNdfAccess::windowedAddImage(*flakes_, fp, kBandFlakeWindow, weight * norm(), out, out_count);
}

RuntimeStatus BandFlakes::draw(const Footprint& fp, double u1, double u2, NdfSample* out,
                               const double* known_mass) const {
  if (!out || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0)) return RuntimeStatus::kInvalidArgument;
  double m = 0.0;
  if (known_mass) {
    m = *known_mass;
  } else if (RuntimeStatus st = mass(fp, &m); st != RuntimeStatus::kOk) {
    return st;
  }
  if (!(m > 0.0)) return RuntimeStatus::kInvalidArgument;
  flakes::Lobe g;
  double v1 = 0.5, v2 = 0.5;
  if (RuntimeStatus st = FlakeNdfAccess::windowedPick(*flakes_, fp, kBandFlakeWindow, u1, u2, m / norm(), &g, &v1, &v2);
      st != RuntimeStatus::kOk)
    return st;
  flakes::lobePoint(g, v1, v2, &out->s.x, &out->s.y);
  out->pdf = 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus BandFlakes::sample(const Footprint& fp, double u1, double u2, NdfSample* out) const {
  if (RuntimeStatus st = draw(fp, u1, u2, out); st != RuntimeStatus::kOk) return st;
  if (!flakes::inSquare(out->s)) return RuntimeStatus::kOk;  // pdf 0: a failed sample, as FlakeNdf's
  return pdf(fp, out->s, &out->pdf);
}

HandoverNdf::HandoverNdf(FlakePaths paths, std::unique_ptr<NdfSource> pyramid)
    : paths_(std::move(paths)), band_flakes_(paths_.flakes.get()), pyramid_(std::move(pyramid)) {
  const format::FlakesRecord& r = paths_.record;
  flakes_up_to_ = r.flakes_up_to;
  pyramid_from_ = r.pyramid_from;
  lobes_from_ = lobes_up_to_ = 0.0;
  if (paths_.lobes) {
    // The lobes answer up to the record's bound, and never beyond their own window limit.
    lobes_from_ = r.flakes_up_to * format::kLobesBand;
    const double limit = paths_.lobes->footprintRange().clustered_max_sigma;
    lobes_up_to_ = std::max(lobes_from_, std::min(r.lobes_up_to, limit));
    pyramid_from_ = std::max(pyramid_from_, lobes_up_to_);
    if (pyramid_from_ > limit) {
      // The record's band reaches past what the lobes' window allows (a record whose lobes answer
      // every footprint, on a small map): the pyramid takes over over the half octave below it.
      pyramid_from_ = std::max(lobes_from_, limit);
      lobes_up_to_ = std::max(lobes_from_, std::min(lobes_up_to_, pyramid_from_ / kHalfOctaveWithSlack));
    }
    // The levels the lobes stand in for never answer, not even through the pyramid's own blend
    // (whose deconvolution would otherwise prefer the finest level): the pyramid answers from the
    // first level of at least lobes_up_to / sqrt(2), the level the hand-over was placed above.
    pyramid_->answerFromSigma(lobes_up_to_ / kHalfOctaveWithSlack);
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
  if (!paths_.lobes) return {&band_flakes_, pyramid_.get(), band(sigma, flakes_up_to_, pyramid_from_)};
  const AccumulatingNdfSource* lobes = paths_.lobes.get();
  if (sigma < lobes_from_) return {&band_flakes_, lobes, band(sigma, flakes_up_to_, lobes_from_)};
  if (sigma <= lobes_up_to_) return {lobes, nullptr, 0.0};
  return {lobes, pyramid_.get(), band(sigma, lobes_up_to_, pyramid_from_)};
}

// (1 - t) query(lower) + t query(upper), querying only the paths with a non-zero weight.
template <typename Query>
RuntimeStatus HandoverNdf::blend(const Footprint& fp, double* value, Query&& query) const {
  if (!value || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  const Mix mix = mixFor(fp.sigma);
  double a = 0.0, b = 0.0;
  if (mix.t < 1.0) {
    if (RuntimeStatus s = query(*mix.lower, &a); s != RuntimeStatus::kOk) return s;
  }
  if (mix.t > 0.0) {
    if (RuntimeStatus s = query(*mix.upper, &b); s != RuntimeStatus::kOk) return s;
  }
  *value = mix.t <= 0.0 ? a : (mix.t >= 1.0 ? b : (1.0 - mix.t) * a + mix.t * b);
  return RuntimeStatus::kOk;
}

RuntimeStatus HandoverNdf::eval(const Footprint& fp, const SPoint& s, double* value) const {
  if (value && validFootprint(fp)) {
    // Between the flakes and lobes that answer from the exact flakes in a narrower window, both
    // sums come from one traversal of the flakes.
    const Mix mix = mixFor(fp.sigma);
    double window = 0.0, norm = 0.0;
    if (mix.t > 0.0 && mix.t < 1.0 && mix.lower == &band_flakes_ && paths_.lobes && mix.upper == paths_.lobes.get() &&
        LobeNdfAccess::exactWindow(*paths_.lobes, fp.sigma, &window, &norm) && window <= kBandFlakeWindow) {
      double outer = 0.0, inner = 0.0;
      if (RuntimeStatus st =
              FlakeNdfAccess::evalWithInnerWindow(*paths_.flakes, fp, s, window, kBandFlakeWindow, &outer, &inner);
          st != RuntimeStatus::kOk)
        return st;
      *value = (1.0 - mix.t) * (BandFlakes::norm() * outer) + mix.t * (norm * inner);
      return RuntimeStatus::kOk;
    }
  }
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.eval(fp, s, v); });
}

RuntimeStatus HandoverNdf::average(const Footprint& fp, const SRect& rect, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.average(fp, rect, v); });
}

RuntimeStatus HandoverNdf::mass(const Footprint& fp, double* value) const {
  return blend(fp, value, [&](const NdfSource& src, double* v) { return src.mass(fp, v); });
}

const NdfSource* HandoverNdf::onlyPath(const Mix& mix) {
  if (mix.t <= 0.0) return mix.lower;
  if (mix.t >= 1.0) return mix.upper;
  return nullptr;
}

RuntimeStatus HandoverNdf::pdf(const Footprint& fp, const SPoint& s, double* value) const {
  if (!value) return RuntimeStatus::kInvalidArgument;
  // One path: its own pdf (its eval over its mass, the density its sample reports).
  if (validFootprint(fp)) {
    if (const NdfSource* only = onlyPath(mixFor(fp.sigma))) return only->pdf(fp, s, value);
  }
  double e = 0.0, m = 0.0;
  if (RuntimeStatus st = eval(fp, s, &e); st != RuntimeStatus::kOk) return st;
  if (RuntimeStatus st = mass(fp, &m); st != RuntimeStatus::kOk) return st;
  *value = m > 0.0 ? e / m : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus HandoverNdf::sample(const Footprint& fp, double u1, double u2, NdfSample* out) const {
  if (!out || !validFootprint(fp) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  const Mix mix = mixFor(fp.sigma);
  // One path: its sample and density, which are pdf()'s.
  if (const NdfSource* only = onlyPath(mix)) return only->sample(fp, u1, u2, out);
  // A path in proportion to its weighted mass, u1 rescaled within the choice.
  double ma = 0.0, mb = 0.0;
  if (RuntimeStatus s = mix.lower->mass(fp, &ma); s != RuntimeStatus::kOk) return s;
  if (RuntimeStatus s = mix.upper->mass(fp, &mb); s != RuntimeStatus::kOk) return s;
  const double wa = (1.0 - mix.t) * ma, wb = mix.t * mb;
  if (!(wa + wb > 0.0)) return RuntimeStatus::kInvalidArgument;
  const double x = u1 * (wa + wb);
  const bool first = x < wa;
  const double v = first ? x / wa : (x - wa) / wb;
  const double u = std::fmin(std::fmax(v, 0.0), 0.99999999999999989);
  const NdfSource& src = first ? static_cast<const NdfSource&>(*mix.lower) : *mix.upper;
  // The flakes and lobes draw the point without their own density (the blend's is needed).
  NdfSample picked;
  RuntimeStatus drawn;
  if (&src == &band_flakes_)
    drawn = band_flakes_.draw(fp, u, u2, &picked, first ? &ma : &mb);
  else if (paths_.lobes && &src == paths_.lobes.get())
    drawn = LobeNdfAccess::sample(*paths_.lobes, fp, u, u2, &picked, false, first ? &ma : &mb);
  else
    drawn = src.sample(fp, u, u2, &picked);
  if (drawn != RuntimeStatus::kOk) return drawn;
  // pdf(): the blended eval over the blended mass, the latter from the masses above (mass()'s
  // expression, so the same bits).
  double e = 0.0;
  if (RuntimeStatus s = eval(fp, picked.s, &e); s != RuntimeStatus::kOk) return s;
  const double m = (1.0 - mix.t) * ma + mix.t * mb;
  out->s = picked.s;
  out->pdf = m > 0.0 ? e / m : 0.0;
  return RuntimeStatus::kOk;
}

RuntimeStatus HandoverNdf::image(const Footprint& fp, float* out, size_t out_count) const {
  const int res = pyramid_->resolution();
  const size_t n = size_t(res) * size_t(res);
  if (!out || out_count < n || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  const Mix mix = mixFor(fp.sigma);
  if (mix.t <= 0.0) return mix.lower->image(fp, out, out_count);
  if (mix.t >= 1.0) return mix.upper->image(fp, out, out_count);
  // The upper path's image scaled in place, then the lower path's lobes added on top.
  if (RuntimeStatus s = mix.upper->image(fp, out, out_count); s != RuntimeStatus::kOk) return s;
  for (size_t i = 0; i < n; ++i) out[i] = float(mix.t * double(out[i]));
  return mix.lower->addImage(fp, 1.0 - mix.t, out, out_count);
}

}  // namespace glintbake::runtime
