// SPDX-License-Identifier: Apache-2.0
// The streaming half of the tensor-ndf packer: cuts each region of the pyramid into blocks, drops
// the blank ones, compresses the rest as one group on the TBB pool and writes the finished groups,
// the level indexes and the info record in a fixed order.
#include "tensor/tensor_pack_internal.h"

#include <glintbake/format/kinds/ndf_pyramid.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <string>

namespace glintbake::bake::tensor::detail {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Adds elapsed time to an accumulator when it leaves scope.
class ScopedTimer {
 public:
  explicit ScopedTimer(double& total) : total_(total), t0_(Clock::now()) {}
  ~ScopedTimer() { total_ += secondsSince(t0_); }

 private:
  double& total_;
  Clock::time_point t0_;
};

BakeStatus cancelledError() { return makeError(ErrorCode::kRuntime, "cancelled"); }

}  // namespace

TensorPackSink::TensorPackSink(format::Writer& writer, const TensorPackOptions& options, TensorPackReport& report,
                               const std::atomic<bool>* cancel)
    : writer_(writer), options_(options), report_(report), cancel_(cancel) {
  // Groups in flight: enough to keep every worker busy while the producer splats the next region.
  // Only memory and timing depend on this, never the bytes (groups are written in id order).
  max_in_flight_ = size_t(std::max(1, tbb::this_task_arena::max_concurrency())) + 1;
  bytes_at_start_ = writer_.bytesWritten();
}

TensorPackSink::~TensorPackSink() {
  for (auto& p : pending_) p->task.wait();
}

BakeStatus TensorPackSink::writeSection(uint32_t type, uint64_t key, const void* data, size_t size) {
  ScopedTimer timer(report_.write_seconds);
  if (format::ContainerStatus st = writer_.addSection(type, key, data, size); st != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, std::string("cannot write ") + format::sectionTypeString(type) +
                                         " section: " + writer_.errorString(st));
  }
  return okStatus();
}

BakeStatus TensorPackSink::addLevel(const format::NdfLevelRecord& record) {
  ScopedTimer inside(seconds_inside_);
  if (cancel_ && cancel_->load(std::memory_order_relaxed)) return cancelledError();
  const int res = int(record.ndf_res);
  if (ndf_res_ == 0) {
    if (res < 1 || res % options_.block != 0) {
      return makeError(ErrorCode::kBadArgument, "--block " + std::to_string(options_.block) +
                                                    " does not divide the NDF resolution " + std::to_string(res));
    }
    ndf_res_ = res;
    blocks_per_side_ = res / options_.block;
    report_.ndf_res = res;
    report_.blocks_per_side = blocks_per_side_;
  } else if (res != ndf_res_) {
    return makeError(ErrorCode::kInvalidInput,
                     "level " + std::to_string(record.level) + " has a different NDF resolution than level 0");
  }
  if (format::RecordCheck c = format::checkNdfLevelRecord(record, record.level, level_ >= 0 ? &below_ : nullptr); !c) {
    return makeError(ErrorCode::kRuntime, std::string("level descriptor fails its check: ") + c.detail);
  }
  below_ = record;
  level_ = int(record.level);
  grid_width_ = int(record.grid_width);
  grid_height_ = int(record.grid_height);
  level_bytes_before_ = writer_.bytesWritten();
  try {
    index_.assign(size_t(grid_width_) * size_t(grid_height_) * size_t(blocks_per_side_) * size_t(blocks_per_side_),
                  format::TensorIndexEntry{});
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating the index of level " + std::to_string(level_));
  }
  level_sum_.assign(size_t(res) * size_t(res), 0.0);
  level_images_ = 0;
  const uint64_t level_bytes = uint64_t(grid_width_) * uint64_t(grid_height_) * uint64_t(res) * uint64_t(res) * 4u;
  exact_level_ = options_.exact_level_bytes > 0 && level_bytes <= options_.exact_level_bytes &&
                 uint64_t(grid_width_) * uint64_t(grid_height_) <= kMaxExactCentres &&
                 int(record.level) >= options_.exact_min_level && options_.block <= int(format::kTensorMaxRank);
  TensorPackLevelReport lrep;
  lrep.level = level_;
  lrep.grid_width = grid_width_;
  lrep.grid_height = grid_height_;
  lrep.sigma = record.sigma_texels;
  lrep.exact = exact_level_;
  report_.levels.push_back(lrep);
  return writeSection(format::kSectionNdfLevel, uint64_t(record.level), &record, sizeof(record));
}

BakeStatus TensorPackSink::addChunk(const ndf::PyramidChunk& chunk) {
  ScopedTimer inside(seconds_inside_);
  if (cancel_ && cancel_->load(std::memory_order_relaxed)) return cancelledError();
  GLINTBAKE_CHECK(chunk.level == level_ && chunk.ndf_res == ndf_res_);
  TensorPackLevelReport& lrep = report_.levels.back();
  const int res = ndf_res_, bins = options_.block, nb = blocks_per_side_;
  const size_t image_floats = size_t(res) * size_t(res);
  const double bin_area = (2.0 / res) * (2.0 / res);
  const int centres = chunk.width * chunk.height;
  lrep.raw_bytes += uint64_t(centres) * image_floats * sizeof(float);
  for (int k = 0; k < centres; ++k) {
    const float* image = chunk.images + size_t(k) * image_floats;
    for (size_t i = 0; i < image_floats; ++i) level_sum_[i] += double(image[i]);
  }
  level_images_ += uint64_t(centres);

  // Pass 1: which blocks stay (mass >= threshold and not all zero), in (centre, block) order.
  std::vector<uint8_t> keep(size_t(centres) * size_t(nb) * size_t(nb), 0);
  size_t kept = 0;
  for (int k = 0; k < centres; ++k) {
    const float* image = chunk.images + size_t(k) * image_floats;
    for (int b = 0; b < nb * nb; ++b) {
      const int bx = b % nb, by = b / nb;
      double mass = 0.0, norm_squared = 0.0;
      for (int j = 0; j < bins; ++j) {
        const float* row = image + size_t(by * bins + j) * size_t(res) + size_t(bx * bins);
        for (int i = 0; i < bins; ++i) {
          mass += row[i];
          norm_squared += double(row[i]) * double(row[i]);
        }
      }
      mass *= bin_area;
      const bool blank = norm_squared == 0.0 || mass < options_.blank_threshold;
      if (blank) {
        // A dropped block reconstructs to 0: its whole norm is error.
        lrep.error_squared += norm_squared;
        lrep.norm_squared += norm_squared;
        ++lrep.blocks_dropped;
      } else {
        keep[size_t(k) * nb * nb + size_t(b)] = 1;
        ++kept;
      }
    }
  }
  if (kept == 0) return okStatus();
  if (exact_level_) return addExactBlocks(chunk, keep);

  // Pass 2: copy the kept blocks into the group tensor and point the index at them.
  auto p = std::make_unique<Pending>();
  p->level = level_;
  p->region = chunk.region;
  p->tensor.bins = bins;
  p->tensor.blocks = int(kept);
  try {
    p->tensor.values.resize(kept * size_t(bins) * size_t(bins));
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating a group tensor");
  }
  const uint32_t group = next_group_++;
  uint32_t row = 0;
  for (int k = 0; k < centres; ++k) {
    const float* image = chunk.images + size_t(k) * image_floats;
    const size_t centre = size_t(chunk.y0 + k / chunk.width) * size_t(grid_width_) + size_t(chunk.x0 + k % chunk.width);
    for (int b = 0; b < nb * nb; ++b) {
      if (!keep[size_t(k) * nb * nb + size_t(b)]) continue;
      const int bx = b % nb, by = b / nb;
      float* dst = p->tensor.values.data() + size_t(row) * bins * bins;
      for (int j = 0; j < bins; ++j) {
        std::memcpy(dst + size_t(j) * bins, image + size_t(by * bins + j) * size_t(res) + size_t(bx * bins),
                    size_t(bins) * sizeof(float));
      }
      index_[centre * size_t(nb) * size_t(nb) + size_t(b)] = format::TensorIndexEntry{group, row};
      ++row;
    }
  }
  lrep.blocks_kept += kept;
  ++lrep.groups;

  // Compress on the pool; write the oldest groups once too many are in flight.
  Pending* raw = p.get();
  const TensorPackOptions* options = &options_;
  raw->task.run([raw, options] {
    try {
      raw->result.emplace(compressGroup(raw->tensor, raw->level, raw->region, *options));
    } catch (const std::bad_alloc&) {
      raw->result.emplace(makeError(ErrorCode::kRuntime, "out of memory compressing a group"));
    }
  });
  pending_.push_back(std::move(p));
  while (pending_.size() > max_in_flight_) {
    if (BakeStatus s = writeFront(); !s) return s;
  }
  return okStatus();
}

BakeStatus TensorPackSink::addExactBlocks(const ndf::PyramidChunk& chunk, const std::vector<uint8_t>& keep) {
  TensorPackLevelReport& lrep = report_.levels.back();
  const int res = ndf_res_, bins = options_.block, nb = blocks_per_side_;
  const size_t image_floats = size_t(res) * size_t(res);
  for (int k = 0; k < chunk.width * chunk.height; ++k) {
    const float* image = chunk.images + size_t(k) * image_floats;
    const size_t centre = size_t(chunk.y0 + k / chunk.width) * size_t(grid_width_) + size_t(chunk.x0 + k % chunk.width);
    for (int b = 0; b < nb * nb; ++b) {
      if (!keep[size_t(k) * nb * nb + size_t(b)]) continue;
      const int bx = b % nb, by = b / nb;
      auto p = std::make_unique<Pending>();
      p->level = level_;
      p->region = chunk.region;
      p->tensor.bins = bins;
      p->tensor.blocks = 1;
      try {
        p->tensor.values.resize(size_t(bins) * size_t(bins));
      } catch (const std::bad_alloc&) {
        return makeError(ErrorCode::kRuntime, "out of memory allocating a block");
      }
      for (int j = 0; j < bins; ++j) {
        std::memcpy(p->tensor.values.data() + size_t(j) * bins,
                    image + size_t(by * bins + j) * size_t(res) + size_t(bx * bins), size_t(bins) * sizeof(float));
      }
      index_[centre * size_t(nb) * size_t(nb) + size_t(b)] = format::TensorIndexEntry{next_group_++, 0};
      p->result.emplace(exactGroup(p->tensor, p->level, p->region, options_));
      pending_.push_back(std::move(p));
      ++lrep.blocks_kept;
      ++lrep.groups;
      while (pending_.size() > max_in_flight_) {
        if (BakeStatus s = writeFront(); !s) return s;
      }
    }
  }
  return okStatus();
}

BakeStatus TensorPackSink::writeFront() {
  Pending& p = *pending_.front();
  {
    ScopedTimer wait(report_.wait_seconds);
    p.task.wait();
  }
  Result<EncodedGroup>& result = *p.result;
  if (!result) return result.error();
  const EncodedGroup& g = result.value();
  const uint32_t group = uint32_t(report_.groups);
  if (BakeStatus s = writeSection(format::kSectionTensorGroup, group, g.section.data(), g.section.size()); !s) return s;

  TensorPackLevelReport& lrep = report_.levels.back();
  GLINTBAKE_CHECK(p.level == lrep.level);
  lrep.error_squared += g.error_squared;
  lrep.norm_squared += g.norm_squared;
  report_.cp_seconds += g.seconds;
  report_.negative_mass_fraction += g.negative_mass;  // normalised in finish()
  absolute_mass_ += g.absolute_mass;
  const double group_error = g.norm_squared > 0.0 ? std::sqrt(g.error_squared / g.norm_squared) : 0.0;
  report_.max_group_error = std::max(report_.max_group_error, group_error);
  ++report_.rank_histogram[g.rank];
  report_.max_rank = std::max(report_.max_rank, g.rank);
  ++report_.groups;
  pending_.pop_front();
  return okStatus();
}

BakeStatus TensorPackSink::endLevel(int level) {
  ScopedTimer inside(seconds_inside_);
  GLINTBAKE_CHECK(level == level_);
  while (!pending_.empty()) {
    if (BakeStatus s = writeFront(); !s) return s;
  }
  if (BakeStatus s = writeSection(format::kSectionTensorIndex, uint64_t(level), index_.data(),
                                  index_.size() * sizeof(format::TensorIndexEntry));
      !s) {
    return s;
  }
  TensorPackLevelReport& lrep = report_.levels.back();
  lrep.stored_bytes = writer_.bytesWritten() - level_bytes_before_;
  lrep.relative_error = lrep.norm_squared > 0.0 ? std::sqrt(lrep.error_squared / lrep.norm_squared) : 0.0;
  // |D - mean|^2 = |D|^2 - N |mean|^2 over the level's N images.
  double mean_squared = 0.0;
  if (level_images_ > 0) {
    for (double v : level_sum_) mean_squared += v * v;
    mean_squared /= double(level_images_);
  }
  const double spread_squared = std::max(lrep.norm_squared - mean_squared, 0.0);
  lrep.variation = lrep.norm_squared > 0.0 ? std::sqrt(spread_squared / lrep.norm_squared) : 0.0;
  level_sum_.clear();
  level_sum_.shrink_to_fit();
  index_.clear();
  index_.shrink_to_fit();
  return okStatus();
}

BakeStatus TensorPackSink::finish() {
  ScopedTimer inside(seconds_inside_);
  GLINTBAKE_CHECK(pending_.empty());
  if (report_.groups == 0) {
    return makeError(ErrorCode::kInvalidInput, "every NDF block is blank (block mass below the blank threshold " +
                                                   std::to_string(options_.blank_threshold) + "): nothing to compress");
  }
  format::TensorInfoRecord info;
  info.ndf_res = uint32_t(ndf_res_);
  info.block = uint32_t(options_.block);
  info.blocks_per_side = uint32_t(blocks_per_side_);
  info.level_count = uint32_t(report_.levels.size());
  info.group_count = uint32_t(report_.groups);
  info.max_rank = uint32_t(report_.max_rank);
  info.precision = uint32_t(options_.precision);
  info.flags = options_.cp.nonneg ? format::kTensorFlagNonNegative : 0u;
  info.blank_threshold = options_.blank_threshold;
  if (format::RecordCheck c = format::checkTensorInfoRecord(info); !c) {
    return makeError(ErrorCode::kRuntime, std::string("tensor-info record fails its check: ") + c.detail);
  }
  if (BakeStatus s = writeSection(format::kSectionTensorInfo, 0, &info, sizeof(info)); !s) return s;

  double error_squared = 0.0, norm_squared = 0.0;
  for (const TensorPackLevelReport& l : report_.levels) {
    report_.blocks_kept += l.blocks_kept;
    report_.blocks_dropped += l.blocks_dropped;
    report_.raw_bytes += l.raw_bytes;
    error_squared += l.error_squared;
    norm_squared += l.norm_squared;
  }
  report_.relative_error = norm_squared > 0.0 ? std::sqrt(error_squared / norm_squared) : 0.0;
  report_.negative_mass_fraction = absolute_mass_ > 0.0 ? report_.negative_mass_fraction / absolute_mass_ : 0.0;
  report_.stored_bytes = writer_.bytesWritten() - bytes_at_start_;
  return okStatus();
}

}  // namespace glintbake::bake::tensor::detail
