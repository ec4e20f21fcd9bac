// SPDX-License-Identifier: Apache-2.0
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include "../format_status.h"
#include "../heap_array.h"
#include "../pyramid_blend.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <vector>

namespace glintbake::runtime {
namespace {

constexpr uint64_t kMaxTotalFloats = uint64_t(1) << 36;  // 256 GiB: beyond any sane asset

struct Level {
  NdfLevelRecord rec;
  Array<float> images;   // grid_height * grid_width images of R * R, centre-major row-major
  Array<double> prefix;  // per image R + 1 cumulative row masses
};

// The weighted images of the footprint blend (format::NdfPyramidBlend).
struct Blend {
  int count = 0;
  double weight[format::kMaxBlendCentres];
  const float* image[format::kMaxBlendCentres];
  const double* prefix[format::kMaxBlendCentres];
};

}  // namespace

struct NdfPyramid::Impl {
  int res = 0;
  int level_count = 0;
  double bin = 0.0;       // 2 / R
  double inv_bin = 0.0;   // R / 2
  double bin_area = 0.0;  // (2 / R)^2
  Level levels[kMaxNdfLevels];
  NdfLevelRecord records[kMaxNdfLevels];  // levels[l].rec, contiguous (PyramidNdf::levelRecords)
  PyramidBlender blender;

  RuntimeStatus load(const format::Reader& reader);
  void blend(const Footprint& fp, Blend* b) const;
  // Bin of s, or -1 outside [-1,1]^2.
  int binOf(double sx, double sy) const { return ndfBinOf(sx, sy, res, inv_bin); }
  double blendValue(const Blend& b, int bin_index) const {
    double v = 0.0;
    for (int k = 0; k < b.count; ++k) v += b.weight[k] * double(b.image[k][bin_index]);
    return v;
  }
  double blendMass(const Blend& b) const {
    double m = 0.0;
    for (int k = 0; k < b.count; ++k) m += b.weight[k] * b.prefix[k][res];
    return m;
  }
};

RuntimeStatus NdfPyramid::Impl::load(const format::Reader& reader) {
  std::vector<uint8_t> bytes;
  level_count = 0;
  for (int l = 0; l < kMaxNdfLevels; ++l) {
    const int idx = reader.find(format::kSectionNdfLevel, uint64_t(l));
    if (idx < 0) break;
    if (reader.sections()[size_t(idx)].raw_size != sizeof(NdfLevelRecord)) return RuntimeStatus::kInvalidAsset;
    NdfLevelRecord rec;
    if (RuntimeStatus s = fromFormatStatus(reader.readSectionInto(size_t(idx), &rec, sizeof(rec)));
        s != RuntimeStatus::kOk)
      return s;
    // Descriptor sanity: everything the queries index with is checked here.
    if (RuntimeStatus s =
            fromRecordCheck(format::checkNdfLevelRecord(rec, uint32_t(l), l > 0 ? &levels[l - 1].rec : nullptr));
        s != RuntimeStatus::kOk)
      return s;
    res = int(rec.ndf_res);
    Level& lv = levels[l];
    lv.rec = rec;
    records[l] = rec;
    const uint64_t image_floats = uint64_t(res) * uint64_t(res);
    const uint64_t centres = uint64_t(rec.grid_width) * uint64_t(rec.grid_height);
    if (centres * image_floats > kMaxTotalFloats) return RuntimeStatus::kInvalidAsset;
    if (!lv.images.allocate(size_t(centres * image_floats)) || !lv.prefix.allocate(size_t(centres * (res + 1))))
      return RuntimeStatus::kOutOfMemory;
    const double area = 4.0 / (double(res) * double(res));

    // Chunks: one per region, scattered into centre order.
    for (uint32_t ry = 0; ry < rec.regions_y; ++ry) {
      for (uint32_t rx = 0; rx < rec.regions_x; ++rx) {
        const uint64_t region = uint64_t(ry) * rec.regions_x + rx;
        const int cidx = reader.find(format::kSectionNdfChunk, format::ndfChunkKey(uint32_t(l), region));
        if (cidx < 0) return RuntimeStatus::kInvalidAsset;
        const uint32_t cx0 = rx * rec.region_size, cy0 = ry * rec.region_size;
        const uint32_t cw = std::min(rec.region_size, rec.grid_width - cx0);
        const uint32_t ch = std::min(rec.region_size, rec.grid_height - cy0);
        const uint64_t expected = sizeof(format::ImageSectionHeader) + uint64_t(cw) * ch * image_floats * 4;
        if (reader.sections()[size_t(cidx)].raw_size != expected) return RuntimeStatus::kInvalidAsset;
        Array<uint8_t> chunk;
        if (!chunk.allocate(size_t(expected))) return RuntimeStatus::kOutOfMemory;
        if (RuntimeStatus s = fromFormatStatus(reader.readSectionInto(size_t(cidx), chunk.data, chunk.size));
            s != RuntimeStatus::kOk)
          return s;
        format::ImageSectionHeader header;
        std::memcpy(&header, chunk.data, sizeof(header));
        if (header.magic != format::ImageSectionHeader().magic || header.width != uint32_t(res) ||
            header.height != uint32_t(res) || header.channels != 1 || header.layers != cw * ch)
          return RuntimeStatus::kInvalidAsset;
        const uint8_t* src = chunk.data + sizeof(header);
        for (uint32_t k = 0; k < cw * ch; ++k) {
          const uint64_t centre = uint64_t(cy0 + k / cw) * rec.grid_width + (cx0 + k % cw);
          float* dst = lv.images.data + centre * image_floats;
          std::memcpy(dst, src + uint64_t(k) * image_floats * 4, size_t(image_floats) * 4);
          double* pre = lv.prefix.data + centre * uint64_t(res + 1);
          pre[0] = 0.0;
          for (int j = 0; j < res; ++j) {
            double row = 0.0;
            for (int i = 0; i < res; ++i) {
              const float v = dst[size_t(j) * res + i];
              if (!(v >= 0.0f) || !std::isfinite(v)) return RuntimeStatus::kInvalidAsset;  // NaN, Inf, negative
              row += v;
            }
            pre[j + 1] = pre[j] + row * area;
          }
        }
      }
    }
    level_count = l + 1;
  }
  if (level_count == 0) return RuntimeStatus::kInvalidAsset;
  bin = 2.0 / res;
  inv_bin = res / 2.0;
  bin_area = bin * bin;
  blender.init(records, level_count);
  return RuntimeStatus::kOk;
}

void NdfPyramid::Impl::blend(const Footprint& fp, Blend* b) const {
  const size_t image_floats = size_t(res) * size_t(res);
  b->count = 0;
  blender.blend(fp.x, fp.y, fp.sigma, [&](int level, size_t centre, double weight) {
    const Level& lv = levels[level];
    b->weight[b->count] = weight;
    b->image[b->count] = lv.images.data + centre * image_floats;
    b->prefix[b->count] = lv.prefix.data + centre * size_t(res + 1);
    ++b->count;
  });
}

NdfPyramid::NdfPyramid() = default;
NdfPyramid::~NdfPyramid() = default;

RuntimeStatus NdfPyramid::loadKind(const format::Reader& reader) {
  auto impl = std::unique_ptr<Impl>(new (std::nothrow) Impl());
  if (!impl) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus s = impl->load(reader); s != RuntimeStatus::kOk) return s;
  impl_ = std::move(impl);
  return RuntimeStatus::kOk;
}

void NdfPyramid::reset() { impl_.reset(); }

const NdfLevelRecord* NdfPyramid::levelRecords(int* count) const {
  if (!impl_) return nullptr;
  *count = impl_->level_count;
  return impl_->records;
}

format::NdfPyramidBlend* NdfPyramid::blender() { return impl_ ? &impl_->blender : nullptr; }
const format::NdfPyramidBlend* NdfPyramid::blender() const { return impl_ ? &impl_->blender : nullptr; }

const float* NdfPyramid::centreImage(int l, int i, int j) const {
  const NdfLevelRecord* r = level(l);
  if (!r || i < 0 || j < 0 || uint32_t(i) >= r->grid_width || uint32_t(j) >= r->grid_height) return nullptr;
  const size_t image_floats = size_t(impl_->res) * size_t(impl_->res);
  return impl_->levels[l].images.data + (size_t(j) * r->grid_width + size_t(i)) * image_floats;
}

RuntimeStatus NdfPyramid::evalChecked(const Footprint& footprint, const SPoint& s, double* value) const {
  Blend b;
  impl_->blend(footprint, &b);
  const int bin = impl_->binOf(s.x, s.y);
  *value = bin < 0 ? 0.0 : impl_->blendValue(b, bin);
  return RuntimeStatus::kOk;
}

RuntimeStatus NdfPyramid::averageChecked(const Footprint& footprint, const SRect& rect, double* value) const {
  const Impl& m = *impl_;
  Blend b;
  m.blend(footprint, &b);
  const double x0 = std::max(rect.x0, -1.0), x1 = std::min(rect.x1, 1.0);
  const double y0 = std::max(rect.y0, -1.0), y1 = std::min(rect.y1, 1.0);
  double integral = 0.0;
  if (x1 > x0 && y1 > y0) {
    const int i0 = std::min(m.res - 1, int((x0 + 1.0) / m.bin)), i1 = std::min(m.res - 1, int((x1 + 1.0) / m.bin));
    const int j0 = std::min(m.res - 1, int((1.0 - y1) / m.bin)), j1 = std::min(m.res - 1, int((1.0 - y0) / m.bin));
    for (int j = j0; j <= j1; ++j) {
      const double top = 1.0 - j * m.bin, bottom = 1.0 - (j + 1) * m.bin;
      const double hy = std::min(top, y1) - std::max(bottom, y0);
      if (hy <= 0.0) continue;
      for (int i = i0; i <= i1; ++i) {
        const double left = -1.0 + i * m.bin, right = -1.0 + (i + 1) * m.bin;
        const double hx = std::min(right, x1) - std::max(left, x0);
        if (hx <= 0.0) continue;
        integral += hx * hy * m.blendValue(b, j * m.res + i);
      }
    }
  }
  *value = integral / ((rect.x1 - rect.x0) * (rect.y1 - rect.y0));
  return RuntimeStatus::kOk;
}

RuntimeStatus NdfPyramid::massChecked(const Footprint& footprint, double* value) const {
  Blend b;
  impl_->blend(footprint, &b);
  *value = impl_->blendMass(b);
  return RuntimeStatus::kOk;
}

RuntimeStatus NdfPyramid::pdfChecked(const Footprint& footprint, const SPoint& s, double* value) const {
  Blend b;
  impl_->blend(footprint, &b);
  const double total = impl_->blendMass(b);
  const int bin = impl_->binOf(s.x, s.y);
  *value = (bin < 0 || !(total > 0.0)) ? 0.0 : impl_->blendValue(b, bin) / total;
  return RuntimeStatus::kOk;
}

RuntimeStatus NdfPyramid::sampleChecked(const Footprint& footprint, double u1, double u2, NdfSample* out) const {
  const Impl& m = *impl_;
  Blend b;
  m.blend(footprint, &b);
  const double total = m.blendMass(b);
  if (!(total > 0.0)) return RuntimeStatus::kInvalidArgument;

  // 1. Component by weighted mass (u1 reused, rescaled to [0, 1) within the chosen component).
  double target = u1 * total;
  int c = 0;
  for (; c < b.count - 1; ++c) {
    const double mc = b.weight[c] * b.prefix[c][m.res];
    if (target < mc) break;
    target -= mc;
  }
  while (c > 0 && !(b.weight[c] * b.prefix[c][m.res] > 0.0)) --c;  // never land on an empty component
  const double* pre = b.prefix[c];
  const double comp_mass = pre[m.res];
  double t = std::clamp(target / b.weight[c], 0.0, comp_mass);
  // 2. Row by binary search of the cumulative row masses.
  int row = int(std::upper_bound(pre + 1, pre + m.res + 1, t) - (pre + 1));
  row = std::min(row, m.res - 1);
  while (row > 0 && !(pre[row + 1] - pre[row] > 0.0)) --row;
  const double row_mass = pre[row + 1] - pre[row];
  double fy = row_mass > 0.0 ? (t - pre[row]) / row_mass : 0.5;
  // 3. Column by a scan of the row (u2), remainder jitters x.
  const float* img = b.image[c] + size_t(row) * m.res;
  double row_sum = 0.0;
  for (int i = 0; i < m.res; ++i) row_sum += img[i];
  double tx = u2 * row_sum;
  int col = 0;
  for (; col < m.res - 1; ++col) {
    if (tx < img[col]) break;
    tx -= img[col];
  }
  while (col > 0 && !(img[col] > 0.0f)) --col;
  double fx = img[col] > 0.0f ? tx / img[col] : 0.5;
  constexpr double kBelowOne = 0.99999999999999989;
  fx = std::clamp(fx, 0.0, kBelowOne);
  fy = std::clamp(fy, 0.0, kBelowOne);
  out->s.x = -1.0 + (col + fx) * m.bin;
  out->s.y = 1.0 - (row + fy) * m.bin;
  out->pdf = m.blendValue(b, row * m.res + col) / total;
  return RuntimeStatus::kOk;
}

RuntimeStatus NdfPyramid::imageChecked(const Footprint& footprint, float* out) const {
  const size_t n = size_t(impl_->res) * size_t(impl_->res);
  Blend b;
  impl_->blend(footprint, &b);
  for (size_t i = 0; i < n; ++i) {
    double v = 0.0;
    for (int k = 0; k < b.count; ++k) v += b.weight[k] * double(b.image[k][i]);
    out[i] = float(v);
  }
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime
