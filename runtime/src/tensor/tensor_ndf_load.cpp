// SPDX-License-Identifier: Apache-2.0
// Loading and validation of tensor-ndf assets (formats/SPEC.md section 10.4): the info record,
// the level records, every group (float16 factors widened), every index entry, and the raw block
// masses the sampler chooses blocks by.
#include "tensor_ndf_impl.h"

#include "../format_status.h"

#include <glintbake/format/binary16.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace glintbake::runtime {
namespace {

constexpr uint64_t kMaxIndexEntries = uint64_t(1) << 32;

// Reads a whole section of exactly `size` bytes (kInvalidAsset on a size mismatch).
RuntimeStatus readExact(const format::Reader& reader, int idx, uint64_t size, Array<uint8_t>* out) {
  if (idx < 0 || reader.sections()[size_t(idx)].raw_size != size) return RuntimeStatus::kInvalidAsset;
  if (size > SIZE_MAX || !out->allocate(size_t(size))) return RuntimeStatus::kOutOfMemory;
  return fromFormatStatus(reader.readSectionInto(size_t(idx), out->data, out->size));
}

}  // namespace

RuntimeStatus TensorNdf::Impl::loadGroup(const format::Reader& reader, uint32_t g, Array<uint8_t>* scratch) {
  const int idx = reader.find(format::kSectionTensorGroup, uint64_t(g));
  if (idx < 0) return RuntimeStatus::kInvalidAsset;
  const uint64_t raw_size = reader.sections()[size_t(idx)].raw_size;
  if (raw_size < sizeof(TensorGroupHeader)) return RuntimeStatus::kInvalidAsset;
  TensorGroupHeader h;
  // The reader bounds raw_size (ReaderOptions::max_raw_section_size); the header's fields then
  // decide the exact size the section must have.
  if (RuntimeStatus s = readExact(reader, idx, raw_size, scratch); s != RuntimeStatus::kOk) return s;
  std::memcpy(&h, scratch->data, sizeof(h));
  if (!format::checkTensorGroupHeader(h, info, level_records)) return RuntimeStatus::kInvalidAsset;
  const uint64_t rank = h.rank, b = h.bins, k = h.blocks;
  const uint64_t factor_values = (2 * b + k) * rank;
  const uint64_t prefix_values = 2 * (b + 1) * rank;
  const uint64_t elem = info.precision == 1 ? 2 : 4;
  if (raw_size != format::tensorGroupSectionBytes(b, rank, k, info.precision)) return RuntimeStatus::kInvalidAsset;

  Group& group = groups.data[g];
  if (!group.data.allocate(size_t(factor_values + prefix_values))) return RuntimeStatus::kOutOfMemory;
  const uint8_t* src = scratch->data + sizeof(TensorGroupHeader);
  float* dst = group.data.data;
  for (uint64_t v = 0; v < factor_values; ++v) {
    float f;
    if (elem == 2) {
      uint16_t bits;
      std::memcpy(&bits, src + v * 2, 2);
      f = format::halfToFloat(bits);
    } else {
      std::memcpy(&f, src + v * 4, 4);
    }
    if (!(std::fabs(f) <= kTensorMaxFactor)) return RuntimeStatus::kInvalidAsset;  // NaN, Inf, huge
    if (nonneg && f < 0.0f) return RuntimeStatus::kInvalidAsset;
    dst[v] = f;
  }
  std::memcpy(dst + factor_values, src + factor_values * elem, size_t(prefix_values) * 4);
  for (uint64_t v = 0; v < prefix_values; ++v) {
    if (!(std::fabs(dst[factor_values + v]) <= kTensorMaxPrefix)) return RuntimeStatus::kInvalidAsset;
  }
  group_headers.data[g] = h;
  CpGroupView& view = group.view;
  view.bins = int32_t(b);
  view.rank = int32_t(rank);
  view.blocks = int32_t(k);
  view.a = dst;
  view.b = dst + b * rank;
  view.c = dst + 2 * b * rank;
  view.a_prefix = dst + factor_values;
  view.b_prefix = dst + factor_values + (b + 1) * rank;
  // Prefix sums start at 0 (the sum of no rows).
  for (uint64_t r = 0; r < rank; ++r) {
    if (view.a_prefix[r] != 0.0f || view.b_prefix[r] != 0.0f) return RuntimeStatus::kInvalidAsset;
  }
  // Exact groups (tensorpack's exact levels) have A = identity: queries read their blocks directly.
  view.identity_a = rank == b;
  for (uint64_t i = 0; view.identity_a && i < b; ++i) {
    for (uint64_t r = 0; r < rank; ++r) {
      if (view.a[i * rank + r] != (i == r ? 1.0f : 0.0f)) {
        view.identity_a = false;
        break;
      }
    }
  }
  if (validateCpGroupView(view) != RuntimeStatus::kOk) return RuntimeStatus::kInvalidAsset;
  memory_bytes += (factor_values + prefix_values) * 4;
  return RuntimeStatus::kOk;
}

RuntimeStatus TensorNdf::Impl::loadIndex(const format::Reader& reader, int l, Array<uint8_t>* scratch) {
  TLevel& lv = levels[l];
  const NdfLevelRecord& rec = lv.rec;
  const uint64_t centres = uint64_t(rec.grid_width) * rec.grid_height;
  const uint64_t entries = centres * nb2;
  if (entries > kMaxIndexEntries) return RuntimeStatus::kInvalidAsset;
  const int idx = reader.find(format::kSectionTensorIndex, uint64_t(l));
  if (RuntimeStatus s = readExact(reader, idx, entries * sizeof(TensorIndexEntry), scratch); s != RuntimeStatus::kOk)
    return s;
  if (!lv.index.allocate(size_t(entries)) || !lv.mass.allocate(size_t(entries)) ||
      (nonneg && !lv.centre_mass.allocate(size_t(centres))))
    return RuntimeStatus::kOutOfMemory;
  std::memcpy(lv.index.data, scratch->data, size_t(entries) * sizeof(TensorIndexEntry));
  memory_bytes += entries * (sizeof(TensorIndexEntry) + sizeof(double)) + (nonneg ? centres * sizeof(double) : 0);
  const uint32_t b = info.block;
  for (uint64_t c = 0; c < centres; ++c) {
    const uint32_t cx = uint32_t(c % rec.grid_width), cy = uint32_t(c / rec.grid_width);
    const uint32_t region = (cy / rec.region_size) * rec.regions_x + cx / rec.region_size;
    double centre_mass = 0.0;
    for (uint64_t blk = 0; blk < nb2; ++blk) {
      const uint64_t e_index = c * nb2 + blk;
      const TensorIndexEntry& e = lv.index.data[e_index];
      if (e.group == kTensorBlankGroup) {
        lv.mass.data[e_index] = 0.0;
        continue;
      }
      if (!format::checkTensorIndexEntry(e, group_headers.data, group_count, uint32_t(l), region))
        return RuntimeStatus::kInvalidAsset;
      const Group& g = groups.data[e.group];
      // Raw (unclamped) integral of the block over its s-plane area, from the prefix sums exactly
      // as CpMix::rawRangeSum forms it, in double.
      const int32_t rank = g.view.rank;
      const float* pa0 = g.view.a_prefix;
      const float* pa1 = g.view.a_prefix + size_t(b) * rank;
      const float* pb0 = g.view.b_prefix;
      const float* pb1 = g.view.b_prefix + size_t(b) * rank;
      const float* crow = g.view.c + size_t(e.row) * rank;
      double m = 0.0;
      for (int32_t r = 0; r < rank; ++r) m += (double(pa1[r]) - pa0[r]) * (double(pb1[r]) - pb0[r]) * double(crow[r]);
      // Non-negative factors and monotone prefix sums give m >= 0: anything else is corrupt.
      if (nonneg && !(m >= 0.0)) return RuntimeStatus::kInvalidAsset;
      lv.mass.data[e_index] = m * bin_area;
      centre_mass += m * bin_area;
      ++blocks_kept;
    }
    if (nonneg) lv.centre_mass.data[c] = centre_mass;
  }
  return RuntimeStatus::kOk;
}

RuntimeStatus TensorNdf::Impl::load(const format::Reader& reader) {
  Array<uint8_t> scratch;
  const int info_idx = reader.find(format::kSectionTensorInfo, 0);
  if (RuntimeStatus s = readExact(reader, info_idx, sizeof(TensorInfoRecord), &scratch); s != RuntimeStatus::kOk)
    return s;
  std::memcpy(&info, scratch.data, sizeof(info));
  if (RuntimeStatus s = fromRecordCheck(format::checkTensorInfoRecord(info)); s != RuntimeStatus::kOk) return s;
  res = int(info.ndf_res);
  bins = int(info.block);
  bins_shift = -1;
  for (int k = 0; k < 31; ++k) {
    if (bins == (1 << k)) bins_shift = k;
  }
  nb = int(info.blocks_per_side);
  nb2 = uint64_t(nb) * uint64_t(nb);
  nonneg = (info.flags & kTensorFlagNonNegative) != 0;
  bin = 2.0 / res;
  inv_bin = res / 2.0;
  bin_area = bin * bin;
  inv_bin_area = 1.0 / bin_area;

  for (int l = 0; l < int(info.level_count); ++l) {
    const int idx = reader.find(format::kSectionNdfLevel, uint64_t(l));
    if (RuntimeStatus s = readExact(reader, idx, sizeof(NdfLevelRecord), &scratch); s != RuntimeStatus::kOk) return s;
    std::memcpy(&levels[l].rec, scratch.data, sizeof(NdfLevelRecord));
    level_records[l] = levels[l].rec;
    const NdfLevelRecord* below = l > 0 ? &levels[l - 1].rec : nullptr;
    if (RuntimeStatus s = fromRecordCheck(format::checkTensorLevelRecord(levels[l].rec, uint32_t(l), info, below));
        s != RuntimeStatus::kOk)
      return s;
  }
  level_count = int(info.level_count);
  blender.init(level_records, level_count);

  // Every group needs its own section, so the section count bounds the allocation.
  if (uint64_t(info.group_count) > reader.sections().size()) return RuntimeStatus::kInvalidAsset;
  group_count = info.group_count;
  if (group_count > 0 && (!groups.allocate(group_count) || !group_headers.allocate(group_count)))
    return RuntimeStatus::kOutOfMemory;
  for (uint32_t g = 0; g < group_count; ++g) {
    if (RuntimeStatus s = loadGroup(reader, g, &scratch); s != RuntimeStatus::kOk) return s;
  }
  for (int l = 0; l < level_count; ++l) {
    if (RuntimeStatus s = loadIndex(reader, l, &scratch); s != RuntimeStatus::kOk) return s;
    if (RuntimeStatus s = buildPointLevel(l); s != RuntimeStatus::kOk) return s;
  }
  return RuntimeStatus::kOk;
}

RuntimeStatus TensorNdf::Impl::buildPointLevel(int l) {
  const TLevel& lv = levels[l];
  PointLevel& p = point[l];
  p.centres = uint64_t(lv.rec.grid_width) * lv.rec.grid_height;
  const uint64_t slots = p.centres * nb2;
  // Entries were checked by loadIndex: every group exists and every row lies within it.
  bool exact = true;
  uint64_t stored = 0;
  int32_t stride = 0;
  for (uint64_t e = 0; e < slots; ++e) {
    const TensorIndexEntry& entry = lv.index.data[e];
    if (entry.group == kTensorBlankGroup) continue;
    const CpGroupView& v = groups.data[entry.group].view;
    exact = exact && v.identity_a;
    stride = std::max(stride, v.rank);
    ++stored;
  }
  if (stored > uint64_t(UINT32_MAX)) return RuntimeStatus::kOutOfMemory;  // (rows numbered in 32 bits)
  const uint64_t bins2 = uint64_t(bins) * uint64_t(bins);
  // Dense only when at least half the blocks are stored: its values then take at most twice the
  // stored blocks' B factors.
  p.dense = exact && stored > 0 && 2 * stored >= slots && slots * bins2 * sizeof(float) <= kPointDenseBytes;
  if (p.dense) {
    if (!p.values.allocate(size_t(slots * bins2))) return RuntimeStatus::kOutOfMemory;
    for (uint64_t c = 0; c < p.centres; ++c) {
      for (uint64_t block = 0; block < nb2; ++block) {
        const TensorIndexEntry& e = lv.index.data[c * nb2 + block];
        float* dst = p.values.data + block * bins2 * p.centres + c;
        if (e.group == kTensorBlankGroup) {
          for (uint64_t k = 0; k < bins2; ++k) dst[k * p.centres] = 0.0f;
          continue;
        }
        // An exact block's bin (bi, bj) is C[row, bi] B[bj, bi] (A is the identity).
        const CpGroupView& v = groups.data[e.group].view;
        const float* crow = v.c + size_t(e.row) * size_t(v.rank);
        for (int bj = 0; bj < bins; ++bj) {
          for (int bi = 0; bi < bins; ++bi)
            dst[(uint64_t(bj) * bins + bi) * p.centres] = crow[bi] * v.b[size_t(bj) * size_t(v.rank) + size_t(bi)];
        }
      }
    }
    memory_bytes += p.values.size * sizeof(float);
    return RuntimeStatus::kOk;
  }
  p.row_stride = stride;
  if (!p.slots.allocate(size_t(slots)) || !p.rows.allocate(size_t(stored * uint64_t(stride))))
    return RuntimeStatus::kOutOfMemory;
  uint32_t next = 0;
  for (uint64_t block = 0; block < nb2; ++block) {
    for (uint64_t c = 0; c < p.centres; ++c) {
      const TensorIndexEntry& e = lv.index.data[c * nb2 + block];
      PointSlot& slot = p.slots.data[block * p.centres + c];
      slot.group = e.group;
      if (e.group == kTensorBlankGroup) continue;
      slot.row = next;
      float* row = p.rows.data + uint64_t(next++) * uint64_t(stride);
      const CpGroupView& v = groups.data[e.group].view;
      std::fill(row, row + stride, 0.0f);
      std::copy(v.c + size_t(e.row) * size_t(v.rank), v.c + size_t(e.row + 1) * size_t(v.rank), row);
    }
  }
  memory_bytes += p.slots.size * sizeof(PointSlot) + p.rows.size * sizeof(float);
  return RuntimeStatus::kOk;
}

TensorNdf::TensorNdf() = default;
TensorNdf::~TensorNdf() = default;

RuntimeStatus TensorNdf::loadKind(const format::Reader& reader) {
  std::unique_ptr<Impl> impl(new (std::nothrow) Impl());
  if (!impl) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus s = impl->load(reader); s != RuntimeStatus::kOk) return s;
  impl_ = std::move(impl);
  return RuntimeStatus::kOk;
}

void TensorNdf::reset() { impl_.reset(); }

const NdfLevelRecord* TensorNdf::levelRecords(int* count) const {
  if (!impl_) return nullptr;
  *count = impl_->level_count;
  return impl_->level_records;
}

format::NdfPyramidBlend* TensorNdf::blender() { return impl_ ? &impl_->blender : nullptr; }
const format::NdfPyramidBlend* TensorNdf::blender() const { return impl_ ? &impl_->blender : nullptr; }

const TensorInfoRecord* TensorNdf::info() const { return impl_ ? &impl_->info : nullptr; }
int TensorNdf::groupCount() const { return impl_ ? int(impl_->group_count) : 0; }
uint64_t TensorNdf::blocksKept() const { return impl_ ? impl_->blocks_kept : 0; }
uint64_t TensorNdf::memoryBytes() const { return impl_ ? impl_->memory_bytes : 0; }

const CpGroupView* TensorNdf::group(int g) const {
  if (!impl_ || g < 0 || uint32_t(g) >= impl_->group_count) return nullptr;
  return &impl_->groups.data[g].view;
}

const TensorIndexEntry* TensorNdf::indexEntry(int l, int i, int j, int block) const {
  const NdfLevelRecord* r = level(l);
  if (!r || i < 0 || j < 0 || uint32_t(i) >= r->grid_width || uint32_t(j) >= r->grid_height || block < 0 ||
      uint64_t(block) >= impl_->nb2)
    return nullptr;
  const uint64_t centre = uint64_t(j) * r->grid_width + uint64_t(i);
  return &impl_->levels[l].index.data[centre * impl_->nb2 + uint64_t(block)];
}

}  // namespace glintbake::runtime
