// SPDX-License-Identifier: Apache-2.0
// Wang-tiles assets: loading the tile set and each tile's NDF asset, and answering footprints as
// sums over the tiles they cover (see wang_ndf.h).
#include <glintbake/runtime/wang_ndf.h>

#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/tensor_ndf.h>
#include "../format_status.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::runtime {
namespace {

constexpr double kMaxPosition = 1e15;  // texels; beyond, cell and local coordinates lose precision
constexpr int kMaxTerms = 18;          // 3 x 3 tiles, on two paths in the hand-over band

bool sectionHasSize(const format::Reader& reader, uint32_t type, size_t size) {
  const int idx = reader.find(type, 0);
  return idx >= 0 && reader.sections()[size_t(idx)].raw_size == size;
}

// Footprints a Wang-tile query accepts (positions up to kMaxPosition inclusive).
bool validWangFootprint(const Footprint& f) {
  return std::isfinite(f.x) && std::isfinite(f.y) && std::fabs(f.x) <= kMaxPosition && std::fabs(f.y) <= kMaxPosition &&
         std::isfinite(f.sigma) && f.sigma >= 0.0;
}

uint32_t tileOfCell(const format::WangRecord& rec, const uint32_t* code_to_tile, int64_t i, int64_t j) {
  uint8_t e[4];
  format::wangCellEdges(i, j, rec.colors, rec.seed, e);
  return code_to_tile[format::wangTileCode(rec.colors, e)];
}

}  // namespace

struct WangNdf::Impl {
  format::WangRecord rec;
  std::unique_ptr<uint32_t[]> code_to_tile;
  std::unique_ptr<float[]> texels;
  std::unique_ptr<std::unique_ptr<NdfSource>[]> assets;  // per tile
  std::unique_ptr<std::unique_ptr<FlakeNdf>[]> flakes;   // per tile; null without an exact path
  double pyramid_min_sigma = 0.0;

  struct Term {
    const NdfSource* source;
    Footprint local;
    double weight;
    bool exact;  // a tile's flakes (else its NDF asset)
  };

  // The terms of a footprint (valid, sigma clamped), in a fixed order: flakes, then assets; each
  // by cell row, then column.
  int terms(const Footprint& f, Term* out) const {
    const double sigma = std::min(f.sigma, rec.max_sigma);
    double t = 1.0;  // weight of the tiles' assets
    if (flakes && sigma < rec.pyramid_from) {
      if (sigma <= rec.flakes_up_to)
        t = 0.0;
      else if (rec.flakes_up_to > 0.0)
        t = std::log(sigma / rec.flakes_up_to) / std::log(rec.pyramid_from / rec.flakes_up_to);
    }
    int n = 0;
    const double T = double(rec.tile_size);
    const auto add = [&](double radius, double weight, bool exact) {
      const int64_t i0 = int64_t(std::floor((f.x - radius) / T)), j0 = int64_t(std::floor((f.y - radius) / T));
      const int64_t i1 = std::min(int64_t(std::floor((f.x + radius) / T)), i0 + 2);
      const int64_t j1 = std::min(int64_t(std::floor((f.y + radius) / T)), j0 + 2);
      const double shift = exact ? 0.0 : double(rec.margin);
      for (int64_t j = j0; j <= j1; ++j) {
        for (int64_t i = i0; i <= i1; ++i) {
          const uint32_t tile = tileOfCell(rec, code_to_tile.get(), i, j);
          const NdfSource* src = exact ? static_cast<const NdfSource*>(flakes[tile].get()) : assets[tile].get();
          out[n++] = {src, {f.x - double(i) * T + shift, f.y - double(j) * T + shift, sigma}, weight, exact};
        }
      }
    };
    if (t < 1.0) add(1.5 * format::wangCoverRadius(sigma) + 1.0, 1.0 - t, true);
    if (t > 0.0) add(format::wangCoverRadius(sigma), t, false);
    return n;
  }

  template <typename Query>
  RuntimeStatus sum(const Footprint& f, double* value, Query&& query) const {
    if (!validWangFootprint(f)) return RuntimeStatus::kInvalidArgument;
    Term terms_[kMaxTerms];
    const int n = terms(f, terms_);
    double total = 0.0;
    for (int k = 0; k < n; ++k) {
      double v = 0.0;
      if (RuntimeStatus s = query(*terms_[k].source, terms_[k].local, &v); s != RuntimeStatus::kOk) return s;
      total += terms_[k].weight * v;
    }
    *value = total;
    return RuntimeStatus::kOk;
  }

  RuntimeStatus massSum(const Footprint& f, double* value) const {
    return sum(f, value, [](const NdfSource& src, const Footprint& l, double* v) { return src.mass(l, v); });
  }
  RuntimeStatus evalSum(const Footprint& f, const SPoint& s, double* value) const {
    if (!std::isfinite(s.x) || !std::isfinite(s.y)) return RuntimeStatus::kInvalidArgument;
    return sum(f, value, [&](const NdfSource& src, const Footprint& l, double* v) { return src.eval(l, s, v); });
  }
  RuntimeStatus pdfAt(const Footprint& f, const SPoint& s, double* value) const {
    double e = 0.0, m = 0.0;
    if (RuntimeStatus st = evalSum(f, s, &e); st != RuntimeStatus::kOk) return st;
    if (RuntimeStatus st = massSum(f, &m); st != RuntimeStatus::kOk) return st;
    *value = m > 0.0 ? e / m : 0.0;
    return RuntimeStatus::kOk;
  }
};

WangNdf::WangNdf() = default;
WangNdf::~WangNdf() = default;

RuntimeStatus WangNdf::load(const format::Reader& reader) {
  impl_.reset();
  if (reader.kind() != format::AssetKind::kWangTiles) return RuntimeStatus::kWrongKind;
  std::unique_ptr<Impl> impl(new (std::nothrow) Impl());
  if (!impl) return RuntimeStatus::kOutOfMemory;
  format::WangRecord& rec = impl->rec;
  if (RuntimeStatus s = readSectionExact(reader, format::kSectionWangInfo, &rec, sizeof rec); s != RuntimeStatus::kOk)
    return s;
  if (rec.magic == format::WangRecord().magic && rec.version > 1) return RuntimeStatus::kUnsupportedVersion;
  if (format::checkWangRecord(rec)) return RuntimeStatus::kInvalidAsset;
  const size_t edge_bytes = format::wangEdgesBytes(rec);
  const size_t texel_floats = format::wangTexelsBytes(rec) / sizeof(float);
  // Sizes before allocations: an untrusted record must not make the loader allocate more than the
  // file's sections hold (each within the reader's raw-size cap).
  if (!sectionHasSize(reader, format::kSectionWangEdges, edge_bytes) ||
      !sectionHasSize(reader, format::kSectionWangTexels, texel_floats * sizeof(float)))
    return RuntimeStatus::kInvalidAsset;
  std::unique_ptr<uint8_t[]> edges(new (std::nothrow) uint8_t[edge_bytes]);
  impl->code_to_tile.reset(new (std::nothrow) uint32_t[rec.tile_count]);
  impl->texels.reset(new (std::nothrow) float[texel_floats]);
  impl->assets.reset(new (std::nothrow) std::unique_ptr<NdfSource>[rec.tile_count]);
  if (!edges || !impl->code_to_tile || !impl->texels || !impl->assets) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus s = readSectionExact(reader, format::kSectionWangEdges, edges.get(), edge_bytes);
      s != RuntimeStatus::kOk)
    return s;
  if (format::checkWangEdges(rec, edges.get(), edge_bytes)) return RuntimeStatus::kInvalidAsset;
  std::memcpy(impl->code_to_tile.get(), edges.get(), size_t(rec.tile_count) * 4);
  if (RuntimeStatus s =
          readSectionExact(reader, format::kSectionWangTexels, impl->texels.get(), texel_floats * sizeof(float));
      s != RuntimeStatus::kOk)
    return s;
  for (size_t i = 0; i < texel_floats; ++i) {
    if (!(std::fabs(impl->texels[i]) <= 1.0f)) return RuntimeStatus::kInvalidAsset;
  }
  const int extended = int(rec.tile_size + 2 * rec.margin);
  std::vector<uint8_t> bytes;
  for (uint32_t t = 0; t < rec.tile_count; ++t) {
    const int idx = reader.find(format::kSectionWangTileNdf, t);
    if (idx < 0) return RuntimeStatus::kInvalidAsset;
    if (format::ContainerStatus st = reader.readSection(size_t(idx), &bytes); st != format::ContainerStatus::kOk)
      return fromFormatStatus(st);
    // Only the NDF kinds a tile may hold (never another wang-tiles asset), without flakes; their
    // blend holds the edge centres beyond the extended square (formats/SPEC.md 10.7).
    format::Reader inner;
    if (inner.openMemory(bytes.data(), bytes.size()) != format::ContainerStatus::kOk)
      return RuntimeStatus::kInvalidAsset;
    std::unique_ptr<PyramidNdf> pyramid;
    if (inner.kind() == format::AssetKind::kTensorNdf)
      pyramid.reset(new (std::nothrow) TensorNdf());
    else if (inner.kind() == format::AssetKind::kNdfPyramid)
      pyramid.reset(new (std::nothrow) NdfPyramid());
    else
      return RuntimeStatus::kInvalidAsset;
    if (!pyramid) return RuntimeStatus::kOutOfMemory;
    if (RuntimeStatus s = pyramid->load(inner); s != RuntimeStatus::kOk)
      return s == RuntimeStatus::kOutOfMemory ? s : RuntimeStatus::kInvalidAsset;
    pyramid->holdEdges();
    std::unique_ptr<NdfSource>& asset = impl->assets[t];
    asset = std::move(pyramid);
    const MapSize size = asset->mapSize();
    if (asset->resolution() != int(rec.ndf_res) || size.width != extended || size.height != extended)
      return RuntimeStatus::kInvalidAsset;
    if (t == 0) impl->pyramid_min_sigma = asset->footprintRange().pyramid_min_sigma;
  }
  if (rec.pyramid_from > 0.0) {
    impl->flakes.reset(new (std::nothrow) std::unique_ptr<FlakeNdf>[rec.tile_count]);
    if (!impl->flakes) return RuntimeStatus::kOutOfMemory;
    const int T = int(rec.tile_size);
    for (uint32_t t = 0; t < rec.tile_count; ++t) {
      impl->flakes[t].reset(new (std::nothrow) FlakeNdf());
      if (!impl->flakes[t]) return RuntimeStatus::kOutOfMemory;
      // The tile alone, clamped: its edges continue as the grid does (formats/SPEC.md 10.7).
      const InterleavedTexels texels(T, T, false, impl->texels.get() + size_t(t) * size_t(T) * size_t(T) * 2, 2);
      if (RuntimeStatus s = impl->flakes[t]->build(texels, int(rec.rate), rec.sigma_r, int(rec.ndf_res));
          s != RuntimeStatus::kOk)
        return s == RuntimeStatus::kOutOfMemory ? s : RuntimeStatus::kInvalidAsset;
    }
  }
  impl_ = std::move(impl);
  return RuntimeStatus::kOk;
}

int WangNdf::resolution() const { return impl_ ? int(impl_->rec.ndf_res) : 0; }

FootprintRange WangNdf::footprintRange() const {
  FootprintRange r;
  if (!impl_) return r;
  r.pyramid_min_sigma = impl_->pyramid_min_sigma;
  r.pyramid_max_sigma = impl_->rec.max_sigma;
  if (impl_->flakes) {
    r.exact_max_sigma = impl_->rec.flakes_up_to;
    r.handover_max_sigma = impl_->rec.pyramid_from;
  }
  return r;
}

MapSize WangNdf::mapSize() const {
  if (!impl_) return {};
  return {int(impl_->rec.tile_size), int(impl_->rec.tile_size)};
}

const format::WangRecord& WangNdf::record() const {
  static const format::WangRecord kEmpty{};
  return impl_ ? impl_->rec : kEmpty;
}

uint32_t WangNdf::cellTile(int64_t i, int64_t j) const {
  return impl_ ? tileOfCell(impl_->rec, impl_->code_to_tile.get(), i, j) : 0;
}

const float* WangNdf::tileTexels() const { return impl_ ? impl_->texels.get() : nullptr; }

int WangNdf::coveredTiles(const Footprint& f) const {
  if (!impl_ || !validWangFootprint(f)) return 0;
  Impl::Term terms[kMaxTerms];
  const int n = impl_->terms(f, terms);
  int exact = 0;
  for (int k = 0; k < n; ++k) exact += terms[k].exact ? 1 : 0;
  return std::max(exact, n - exact);  // in the hand-over band each tile has two terms
}

RuntimeStatus WangNdf::eval(const Footprint& f, const SPoint& s, double* value) const {
  if (!impl_ || !value) return RuntimeStatus::kInvalidArgument;
  return impl_->evalSum(f, s, value);
}

RuntimeStatus WangNdf::average(const Footprint& f, const SRect& rect, double* value) const {
  if (!impl_ || !value) return RuntimeStatus::kInvalidArgument;
  return impl_->sum(f, value,
                    [&](const NdfSource& src, const Footprint& l, double* v) { return src.average(l, rect, v); });
}

RuntimeStatus WangNdf::mass(const Footprint& f, double* value) const {
  if (!impl_ || !value) return RuntimeStatus::kInvalidArgument;
  return impl_->massSum(f, value);
}

RuntimeStatus WangNdf::pdf(const Footprint& f, const SPoint& s, double* value) const {
  if (!impl_ || !value) return RuntimeStatus::kInvalidArgument;
  return impl_->pdfAt(f, s, value);
}

RuntimeStatus WangNdf::sample(const Footprint& f, double u1, double u2, NdfSample* out) const {
  if (!impl_ || !out || !validWangFootprint(f) || !(u1 >= 0.0 && u1 < 1.0) || !(u2 >= 0.0 && u2 < 1.0))
    return RuntimeStatus::kInvalidArgument;
  Impl::Term terms[kMaxTerms];
  double masses[kMaxTerms];
  const int n = impl_->terms(f, terms);
  double total = 0.0;
  for (int k = 0; k < n; ++k) {
    double m = 0.0;
    if (RuntimeStatus s = terms[k].source->mass(terms[k].local, &m); s != RuntimeStatus::kOk) return s;
    masses[k] = terms[k].weight * std::max(m, 0.0);
    total += masses[k];
  }
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;
  // The term holding u1 * total, and u1 rescaled within it.
  const double target = u1 * total;
  double before = 0.0;
  int pick = -1;
  for (int k = 0; k < n; ++k) {
    if (masses[k] <= 0.0) continue;
    pick = k;
    if (target < before + masses[k]) break;
    before += masses[k];
  }
  const double v = std::clamp((target - before) / masses[pick], 0.0, 0.99999999999999989);
  NdfSample inner;
  if (RuntimeStatus s = terms[pick].source->sample(terms[pick].local, v, u2, &inner); s != RuntimeStatus::kOk) return s;
  double p = 0.0;
  if (RuntimeStatus s = impl_->pdfAt(f, inner.s, &p); s != RuntimeStatus::kOk) return s;
  out->s = inner.s;
  out->pdf = p;
  return RuntimeStatus::kOk;
}

RuntimeStatus WangNdf::image(const Footprint& f, float* out, size_t out_count) const {
  if (!impl_ || !out || !validWangFootprint(f)) return RuntimeStatus::kInvalidArgument;
  const size_t n = size_t(impl_->rec.ndf_res) * size_t(impl_->rec.ndf_res);
  if (out_count < n) return RuntimeStatus::kInvalidArgument;
  thread_local std::unique_ptr<float[]> scratch;
  thread_local size_t scratch_size = 0;
  if (scratch_size < n) {
    scratch.reset(new (std::nothrow) float[n]);
    scratch_size = scratch ? n : 0;
    if (!scratch) return RuntimeStatus::kOutOfMemory;
  }
  Impl::Term terms[kMaxTerms];
  const int count = impl_->terms(f, terms);
  for (size_t i = 0; i < n; ++i) out[i] = 0.0f;
  for (int k = 0; k < count; ++k) {
    if (RuntimeStatus s = terms[k].source->image(terms[k].local, scratch.get(), n); s != RuntimeStatus::kOk) return s;
    const float w = float(terms[k].weight);
    for (size_t i = 0; i < n; ++i) out[i] += w * scratch[i];
  }
  return RuntimeStatus::kOk;
}

WangGridTexels::WangGridTexels(const WangNdf& asset, int64_t i0, int64_t j0, int nx, int ny)
    : texels_(asset.tileTexels()), tile_size_(int(asset.record().tile_size)), nx_(nx), ny_(ny) {
  tiles_.resize(size_t(nx) * size_t(ny));
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) tiles_[size_t(j) * size_t(nx) + size_t(i)] = asset.cellTile(i0 + i, j0 + j);
  }
}

void WangGridTexels::normal(int x, int y, float out[2]) const {
  const int T = tile_size_;
  const uint32_t t = tiles_[size_t(y / T) * size_t(nx_) + size_t(x / T)];
  const float* n = texels_ + ((size_t(t) * size_t(T) + size_t(y % T)) * size_t(T) + size_t(x % T)) * 2;
  out[0] = n[0];
  out[1] = n[1];
}

}  // namespace glintbake::runtime
