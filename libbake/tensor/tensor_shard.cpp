// SPDX-License-Identifier: Apache-2.0
// The shard side of a sharded tensor-ndf bake and the replay of its units (bake/tensor/tensor_shard.h).
#include <glintbake/bake/tensor/tensor_shard.h>

#include <glintbake/format/kinds/partial.h>

#include <algorithm>
#include <cstring>
#include <new>
#include <string>
#include <utility>

namespace glintbake::bake::tensor {
namespace {

Error invalidShard(const std::string& message) { return makeError(ErrorCode::kInvalidInput, message); }

template <typename T>
void append(std::vector<uint8_t>& out, const T* values, size_t count) {
  const size_t at = out.size();
  out.resize(at + count * sizeof(T));
  if (count) std::memcpy(out.data() + at, values, count * sizeof(T));
}

}  // namespace

TensorShardRecorder::TensorShardRecorder(format::Writer& partial, int asset_zstd_level, int block,
                                         std::function<uint64_t(int, int)> unit_of)
    : writer_(partial), encoder_(asset_zstd_level), block_(block), unit_of_(std::move(unit_of)) {}

BakeStatus TensorShardRecorder::level(const format::NdfLevelRecord& record) {
  levels_.push_back(record);
  return okStatus();
}

BakeStatus TensorShardRecorder::region(const RegionSummary& s) {
  const format::NdfLevelRecord& rec = levels_.back();
  format::TensorShardRegionRecord r;
  r.level = uint32_t(s.level);
  r.region = uint32_t(s.region);
  r.x0 = uint32_t(s.x0);
  r.y0 = uint32_t(s.y0);
  r.width = uint32_t(s.width);
  r.height = uint32_t(s.height);
  r.ndf_res = rec.ndf_res;
  r.group_count = uint32_t(s.group_count);
  r.blocks_kept = s.blocks_kept;
  r.blocks_dropped = s.blocks_dropped;
  r.dropped_squared = s.dropped_squared;
  r.blocks_per_side = rec.ndf_res / uint32_t(block_);
  const size_t per_centre = size_t(r.blocks_per_side) * r.blocks_per_side;
  try {
    head_.clear();
    groups_.clear();
    bytes_.clear();
    append(head_, &r, 1);
    append(head_, s.image_sum, size_t(rec.ndf_res) * size_t(rec.ndf_res));
    append(head_, s.index, per_centre * size_t(s.width) * size_t(s.height));
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory recording a region");
  }
  unit_ = unit_of_(s.level, s.region);
  return okStatus();
}

BakeStatus TensorShardRecorder::group(const GroupStats& g, const uint8_t* raw, size_t raw_size, const uint8_t* stored,
                                      size_t stored_size, format::Codec codec) {
  format::TensorShardGroupRecord gr;
  gr.rank = uint32_t(g.rank);
  gr.blocks = uint32_t(g.blocks);
  gr.raw_size = raw_size;
  gr.error_squared = g.error_squared;
  gr.norm_squared = g.norm_squared;
  gr.negative_mass = g.negative_mass;
  gr.absolute_mass = g.absolute_mass;
  gr.error_l1 = g.error_l1;
  gr.data_l1 = g.data_l1;
  try {
    if (raw) {
      format::Codec used = format::Codec::kRaw;
      if (format::ContainerStatus st = encoder_.encode(raw, raw_size, format::Codec::kZstd, &stored_, &used);
          st != format::ContainerStatus::kOk)
        return makeError(ErrorCode::kRuntime, std::string("cannot encode a group: ") + format::statusString(st));
      gr.codec = uint32_t(used);
      gr.stored_size = stored_.size();
      append(bytes_, stored_.data(), stored_.size());
    } else {
      gr.codec = uint32_t(codec);
      gr.stored_size = stored_size;
      append(bytes_, stored, stored_size);
    }
    append(groups_, &gr, 1);
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory recording a group");
  }
  return okStatus();
}

BakeStatus TensorShardRecorder::endRegion() {
  try {
    head_.insert(head_.end(), groups_.begin(), groups_.end());
    head_.insert(head_.end(), bytes_.begin(), bytes_.end());
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory recording a region");
  }
  if (format::ContainerStatus st = writer_.addSection(format::kSectionShardUnit, unit_, head_.data(), head_.size());
      st != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, "cannot write a shard-unit section: " + writer_.errorString(st));
  ++regions_;
  std::vector<uint8_t>().swap(head_);
  std::vector<uint8_t>().swap(bytes_);
  return okStatus();
}

BakeStatus TensorShardRecorder::finish() {
  if (format::ContainerStatus st = writer_.addSection(format::kSectionShardLevels, 0, levels_.data(),
                                                      levels_.size() * sizeof(format::NdfLevelRecord));
      st != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, "cannot write the shard-levels section: " + writer_.errorString(st));
  return okStatus();
}

BakeStatus replayTensorRegion(const uint8_t* data, size_t size, TensorRegionConsumer& consumer) {
  format::TensorShardRegionLayout layout;
  if (const char* why = format::checkTensorShardRegion(data, size, &layout)) return invalidShard(why);
  const format::TensorShardRegionRecord& r = layout.record;
  std::vector<double> image_sum(size_t(r.ndf_res) * r.ndf_res);
  std::memcpy(image_sum.data(), data + layout.image_sum, image_sum.size() * sizeof(double));
  std::vector<format::TensorIndexEntry> index(size_t(layout.index_entries));
  std::memcpy(index.data(), data + layout.index, index.size() * sizeof(format::TensorIndexEntry));
  RegionSummary s;
  s.level = int(r.level);
  s.region = int(r.region);
  s.x0 = int(r.x0);
  s.y0 = int(r.y0);
  s.width = int(r.width);
  s.height = int(r.height);
  s.group_count = int(r.group_count);
  s.blocks_kept = r.blocks_kept;
  s.blocks_dropped = r.blocks_dropped;
  s.dropped_squared = r.dropped_squared;
  s.image_sum = image_sum.data();
  s.index = index.data();
  if (BakeStatus st = consumer.region(s); !st) return st;
  size_t at = layout.bytes;
  for (uint32_t g = 0; g < r.group_count; ++g) {
    format::TensorShardGroupRecord gr;
    std::memcpy(&gr, data + layout.groups + size_t(g) * sizeof(gr), sizeof(gr));
    GroupStats stats;
    stats.rank = int(std::min<uint32_t>(gr.rank, 1u << 20));
    stats.blocks = int(std::min<uint32_t>(gr.blocks, 1u << 30));
    stats.error_squared = gr.error_squared;
    stats.norm_squared = gr.norm_squared;
    stats.negative_mass = gr.negative_mass;
    stats.absolute_mass = gr.absolute_mass;
    stats.error_l1 = gr.error_l1;
    stats.data_l1 = gr.data_l1;
    if (BakeStatus st = consumer.group(stats, nullptr, size_t(gr.raw_size), data + at, size_t(gr.stored_size),
                                       format::Codec(gr.codec));
        !st)
      return st;
    at += size_t(gr.stored_size);
  }
  return consumer.endRegion();
}

}  // namespace glintbake::bake::tensor
