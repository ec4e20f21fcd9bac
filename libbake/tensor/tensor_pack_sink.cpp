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

TensorPackSink::TensorPackSink(TensorRegionConsumer& consumer, const TensorPackOptions& options,
                               TensorPackReport& report, const std::atomic<bool>* cancel, const format::Writer* writer)
    : consumer_(consumer), writer_(writer), options_(options), report_(report), cancel_(cancel) {
  // Regions in flight: enough to keep every worker busy while the producer splats the next region.
  // Only memory and timing depend on this, never the bytes (regions are handed on in order).
  max_in_flight_ = size_t(std::max(1, tbb::this_task_arena::max_concurrency())) + 1;
}

TensorPackSink::~TensorPackSink() {
  for (auto& p : pending_) p->task.wait();
}

BakeStatus TensorPackSink::addLevel(const format::NdfLevelRecord& record) {
  ScopedTimer inside(seconds_inside_);
  if (cancel_ && cancel_->load(std::memory_order_relaxed)) return cancelledError();
  const int res = int(record.ndf_res);
  if (ndf_res_ == 0) {
    if (BakeStatus s = checkBlockDividesResolution(options_.block, res); !s) return s;
    ndf_res_ = res;
    blocks_per_side_ = res / options_.block;
  } else if (res != ndf_res_) {
    return makeError(ErrorCode::kInvalidInput,
                     "level " + std::to_string(record.level) + " has a different NDF resolution than level 0");
  }
  level_ = int(record.level);
  grid_width_ = int(record.grid_width);
  exact_level_ = isExactLevel(record, options_);
  return consumer_.level(record);
}

BakeStatus TensorPackSink::push(std::unique_ptr<Pending> p) {
  pending_.push_back(std::move(p));
  while (pending_.size() > max_in_flight_) {
    if (BakeStatus s = writeFront(); !s) return s;
  }
  return okStatus();
}

BakeStatus TensorPackSink::skipChunk(int level, int region) {
  ScopedTimer inside(seconds_inside_);
  auto p = std::make_unique<Pending>();
  p->skipped = true;
  p->summary.level = level;
  p->summary.region = region;
  return push(std::move(p));
}

BakeStatus TensorPackSink::addChunk(const ndf::PyramidChunk& chunk) {
  ScopedTimer inside(seconds_inside_);
  if (cancel_ && cancel_->load(std::memory_order_relaxed)) return cancelledError();
  GLINTBAKE_CHECK(chunk.level == level_ && chunk.ndf_res == ndf_res_);
  const int res = ndf_res_, bins = options_.block, nb = blocks_per_side_;
  const size_t image_floats = size_t(res) * size_t(res);
  const double bin_area = (2.0 / res) * (2.0 / res);
  const int centres = chunk.width * chunk.height;
  const size_t nb2 = size_t(nb) * size_t(nb);

  auto p = std::make_unique<Pending>();
  RegionSummary& s = p->summary;
  s.level = chunk.level;
  s.region = chunk.region;
  s.x0 = chunk.x0;
  s.y0 = chunk.y0;
  s.width = chunk.width;
  s.height = chunk.height;
  try {
    p->image_sum.assign(image_floats, 0.0);
    p->index.assign(size_t(centres) * nb2, format::TensorIndexEntry{});
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory for a region's index");
  }
  for (int k = 0; k < centres; ++k) {
    const float* image = chunk.images + size_t(k) * image_floats;
    for (size_t i = 0; i < image_floats; ++i) p->image_sum[i] += double(image[i]);
  }

  // Pass 1: which blocks stay (mass >= threshold and not all zero), in (centre, block) order.
  std::vector<uint8_t> keep(size_t(centres) * nb2, 0);
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
      if (norm_squared == 0.0 || mass < options_.blank_threshold) {
        // A dropped block reconstructs to 0: its whole norm is error.
        s.dropped_squared += norm_squared;
        ++s.blocks_dropped;
      } else {
        keep[size_t(k) * nb2 + size_t(b)] = 1;
        ++kept;
      }
    }
  }
  s.blocks_kept = kept;
  p->exact = exact_level_;
  s.group_count = kept == 0 ? 0 : exact_level_ ? int(kept) : 1;
  if (kept == 0) return push(std::move(p));

  // Pass 2: copy the kept blocks into the group tensor and point the index at them (exact levels:
  // block n is local group n, row 0; otherwise every block is a row of local group 0).
  p->tensor.bins = bins;
  p->tensor.blocks = int(kept);
  try {
    p->tensor.values.resize(kept * size_t(bins) * size_t(bins));
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating a group tensor");
  }
  uint32_t row = 0;
  for (int k = 0; k < centres; ++k) {
    const float* image = chunk.images + size_t(k) * image_floats;
    for (int b = 0; b < nb * nb; ++b) {
      if (!keep[size_t(k) * nb2 + size_t(b)]) continue;
      const int bx = b % nb, by = b / nb;
      float* dst = p->tensor.values.data() + size_t(row) * bins * bins;
      for (int j = 0; j < bins; ++j) {
        std::memcpy(dst + size_t(j) * bins, image + size_t(by * bins + j) * size_t(res) + size_t(bx * bins),
                    size_t(bins) * sizeof(float));
      }
      p->index[size_t(k) * nb2 + size_t(b)] =
          exact_level_ ? format::TensorIndexEntry{row, 0} : format::TensorIndexEntry{0, row};
      ++row;
    }
  }

  // Compress on the pool (exact blocks are encoded when handed on: no decomposition, little time).
  if (!exact_level_) {
    Pending* raw = p.get();
    const TensorPackOptions* options = &options_;
    raw->task.run([raw, options] {
      try {
        raw->result.emplace(compressGroup(raw->tensor, raw->summary.level, raw->summary.region, *options));
      } catch (const std::bad_alloc&) {
        raw->result.emplace(makeError(ErrorCode::kRuntime, "out of memory compressing a group"));
      }
    });
  }
  return push(std::move(p));
}

BakeStatus TensorPackSink::writeFront() {
  Pending& p = *pending_.front();
  {
    ScopedTimer wait(report_.wait_seconds);
    p.task.wait();
  }
  if (p.skipped) {
    if (BakeStatus s = consumer_.skipRegion(p.summary.level, p.summary.region); !s) return s;
    pending_.pop_front();
    return okStatus();
  }
  p.summary.image_sum = p.image_sum.data();
  p.summary.index = p.index.data();
  if (BakeStatus s = consumer_.region(p.summary); !s) return s;
  auto hand = [&](const EncodedGroup& g, int blocks) {
    GroupStats stats;
    stats.rank = g.rank;
    stats.blocks = blocks;
    stats.error_squared = g.error_squared;
    stats.norm_squared = g.norm_squared;
    stats.negative_mass = g.negative_mass;
    stats.absolute_mass = g.absolute_mass;
    stats.error_l1 = g.error_l1;
    stats.data_l1 = g.data_l1;
    stats.seconds = g.seconds;
    return consumer_.group(stats, g.section.data(), g.section.size(), nullptr, 0, format::Codec::kRaw);
  };
  if (p.exact) {
    const int bins = options_.block;
    GroupTensor block;
    block.bins = bins;
    block.blocks = 1;
    for (int n = 0; n < p.tensor.blocks; ++n) {
      const float* src = p.tensor.values.data() + size_t(n) * bins * bins;
      block.values.assign(src, src + size_t(bins) * bins);
      Result<EncodedGroup> g = exactGroup(block, p.summary.level, p.summary.region, options_);
      if (!g) return g.error();
      if (BakeStatus s = hand(g.value(), 1); !s) return s;
    }
  } else if (p.summary.group_count > 0) {
    Result<EncodedGroup>& result = *p.result;
    if (!result) return result.error();
    if (BakeStatus s = hand(result.value(), p.tensor.blocks); !s) return s;
  }
  if (BakeStatus s = consumer_.endRegion(); !s) return s;
  pending_.pop_front();
  return okStatus();
}

BakeStatus TensorPackSink::endLevel(int level) {
  ScopedTimer inside(seconds_inside_);
  GLINTBAKE_CHECK(level == level_);
  while (!pending_.empty()) {
    if (BakeStatus s = writeFront(); !s) return s;
  }
  return consumer_.endLevel();
}

BakeStatus TensorPackSink::finish() {
  GLINTBAKE_CHECK(pending_.empty());
  return okStatus();
}

}  // namespace glintbake::bake::tensor::detail
