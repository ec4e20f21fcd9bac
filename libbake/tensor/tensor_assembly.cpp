// SPDX-License-Identifier: Apache-2.0
// The final assembly of a tensor-ndf asset (bake/tensor/tensor_assembly.h): numbers the groups,
// builds each level's index from the regions' local entries, sums the statistics in region order
// and writes the level, group, index and info sections.
#include <glintbake/bake/tensor/tensor_assembly.h>

#include <glintbake/format/kinds/ndf_pyramid.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <new>
#include <string>

namespace glintbake::bake::tensor {
namespace {

using Clock = std::chrono::steady_clock;

Error invalid(const std::string& message) { return makeError(ErrorCode::kInvalidInput, message); }

}  // namespace

BakeStatus checkBlockDividesResolution(int block, int res) {
  if (res >= 1 && block >= 1 && res % block == 0) return okStatus();
  return makeError(ErrorCode::kBadArgument,
                   "--block " + std::to_string(block) + " does not divide the NDF resolution " + std::to_string(res));
}

bool isExactLevel(const format::NdfLevelRecord& record, const TensorPackOptions& options) {
  const uint64_t centres = uint64_t(record.grid_width) * uint64_t(record.grid_height);
  const uint64_t level_bytes = centres * uint64_t(record.ndf_res) * uint64_t(record.ndf_res) * 4u;
  return options.exact_level_bytes > 0 && level_bytes <= options.exact_level_bytes && centres <= kMaxExactCentres &&
         (int(record.level) >= options.exact_min_level || (centres <= kExactAnyLevelCentres && record.wrap == 0)) &&
         options.block <= int(format::kTensorMaxRank);
}

TensorAssembler::TensorAssembler(format::Writer& writer, const TensorPackOptions& options, TensorPackReport& report)
    : writer_(writer), options_(options), report_(report) {
  bytes_at_start_ = writer_.bytesWritten();
}

BakeStatus TensorAssembler::writeSection(uint32_t type, uint64_t key, const void* data, size_t size) {
  const auto t0 = Clock::now();
  const format::ContainerStatus st = writer_.addSection(type, key, data, size);
  report_.write_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  if (st != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, std::string("cannot write ") + format::sectionTypeString(type) +
                                         " section: " + writer_.errorString(st));
  }
  return okStatus();
}

BakeStatus TensorAssembler::level(const format::NdfLevelRecord& record) {
  if (in_region_ || (level_ >= 0 && !index_.empty())) return invalid("a level begins before the last one ended");
  const int res = int(record.ndf_res);
  if (ndf_res_ == 0) {
    if (BakeStatus s = checkBlockDividesResolution(options_.block, res); !s) return s;
    ndf_res_ = res;
    blocks_per_side_ = res / options_.block;
    report_.ndf_res = res;
    report_.blocks_per_side = blocks_per_side_;
  } else if (res != ndf_res_) {
    return invalid("level " + std::to_string(record.level) + " has a different NDF resolution than level 0");
  }
  if (int(record.level) != level_ + 1) return invalid("levels out of order");
  if (format::RecordCheck c = format::checkNdfLevelRecord(record, record.level, level_ >= 0 ? &record_ : nullptr); !c)
    return invalid(std::string("level descriptor fails its check: ") + c.detail);
  if (uint64_t(record.grid_width) * record.grid_height > (uint64_t(1) << 26))
    return invalid("level " + std::to_string(record.level) + ": centre grid out of range");
  record_ = record;
  level_ = int(record.level);
  next_region_ = 0;
  level_bytes_before_ = writer_.bytesWritten();
  try {
    index_.assign(
        size_t(record.grid_width) * size_t(record.grid_height) * size_t(blocks_per_side_) * size_t(blocks_per_side_),
        format::TensorIndexEntry{});
    level_sum_.assign(size_t(res) * size_t(res), 0.0);
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating the index of level " + std::to_string(level_));
  }
  level_images_ = 0;
  TensorPackLevelReport lrep;
  lrep.level = level_;
  lrep.grid_width = int(record.grid_width);
  lrep.grid_height = int(record.grid_height);
  lrep.sigma = record.sigma_texels;
  lrep.exact = isExactLevel(record, options_);
  report_.levels.push_back(lrep);
  return writeSection(format::kSectionNdfLevel, uint64_t(record.level), &record, sizeof(record));
}

BakeStatus TensorAssembler::region(const RegionSummary& s) {
  if (level_ < 0 || in_region_ || s.level != level_) return invalid("a region outside its level");
  const int rx_count = int(record_.regions_x), regions = int(record_.regions_x * record_.regions_y);
  if (s.region != next_region_ || s.region >= regions)
    return invalid("region " + std::to_string(s.region) + " of level " + std::to_string(level_) + " out of order");
  const int size = int(record_.region_size);
  const int rx = s.region % rx_count, ry = s.region / rx_count;
  const int x0 = rx * size, y0 = ry * size;
  const int w = std::min(size, int(record_.grid_width) - x0), h = std::min(size, int(record_.grid_height) - y0);
  const std::string where = "region " + std::to_string(s.region) + " of level " + std::to_string(level_);
  if (s.x0 != x0 || s.y0 != y0 || s.width != w || s.height != h) return invalid(where + ": geometry disagrees");
  const uint64_t blocks = uint64_t(w) * uint64_t(h) * uint64_t(blocks_per_side_) * uint64_t(blocks_per_side_);
  if (s.blocks_kept + s.blocks_dropped != blocks || s.group_count < 0 || uint64_t(s.group_count) > s.blocks_kept ||
      (s.blocks_kept > 0) != (s.group_count > 0) || !s.image_sum || !s.index || !std::isfinite(s.dropped_squared) ||
      s.dropped_squared < 0.0)
    return invalid(where + ": counts disagree");
  if (report_.levels.back().exact ? uint64_t(s.group_count) != s.blocks_kept : s.group_count > 1)
    return invalid(where + ": group count disagrees with the level's storage");

  // The index: local group numbers become asset-wide ones; each group's rows are counted.
  region_rows_.assign(size_t(s.group_count), 0);
  const uint64_t first = report_.groups;
  const size_t nb2 = size_t(blocks_per_side_) * size_t(blocks_per_side_);
  uint64_t kept = 0;
  for (int k = 0; k < w * h; ++k) {
    const size_t centre = size_t(y0 + k / w) * size_t(record_.grid_width) + size_t(x0 + k % w);
    for (size_t b = 0; b < nb2; ++b) {
      format::TensorIndexEntry e = s.index[size_t(k) * nb2 + b];
      if (e.group != format::kTensorBlankGroup) {
        if (e.group >= uint32_t(s.group_count)) return invalid(where + ": index names a missing group");
        region_rows_[e.group] = std::max(region_rows_[e.group], int(std::min<uint32_t>(e.row, 1u << 30)) + 1);
        e.group = uint32_t(first + e.group);
        ++kept;
      }
      index_[centre * nb2 + b] = e;
    }
  }
  if (kept != s.blocks_kept) return invalid(where + ": index disagrees with the kept blocks");

  TensorPackLevelReport& lrep = report_.levels.back();
  lrep.raw_bytes += uint64_t(w) * uint64_t(h) * uint64_t(ndf_res_) * uint64_t(ndf_res_) * sizeof(float);
  lrep.error_squared += s.dropped_squared;
  lrep.norm_squared += s.dropped_squared;
  lrep.blocks_dropped += s.blocks_dropped;
  lrep.blocks_kept += s.blocks_kept;
  for (size_t i = 0; i < level_sum_.size(); ++i) {
    if (!std::isfinite(s.image_sum[i])) return invalid(where + ": non-finite image sum");
    level_sum_[i] += s.image_sum[i];
  }
  level_images_ += uint64_t(w) * uint64_t(h);
  region_ = s;
  region_first_group_ = first;
  region_groups_seen_ = 0;
  in_region_ = true;
  return okStatus();
}

BakeStatus TensorAssembler::group(const GroupStats& g, const uint8_t* raw, size_t raw_size, const uint8_t* stored,
                                  size_t stored_size, format::Codec codec) {
  const std::string where = "region " + std::to_string(region_.region) + " of level " + std::to_string(level_);
  if (!in_region_ || region_groups_seen_ >= region_.group_count) return invalid(where + ": more groups than announced");
  if (g.blocks != region_rows_[size_t(region_groups_seen_)] || g.rank < 1 || g.rank > int(format::kTensorMaxRank) ||
      !std::isfinite(g.error_squared) || !std::isfinite(g.norm_squared) || !std::isfinite(g.negative_mass) ||
      !std::isfinite(g.absolute_mass) || !std::isfinite(g.error_l1) || !std::isfinite(g.data_l1))
    return invalid(where + ": a group disagrees with the region's index");
  const uint64_t expected = format::tensorGroupSectionBytes(uint64_t(options_.block), uint64_t(g.rank),
                                                            uint64_t(g.blocks), uint32_t(options_.precision));
  const uint64_t id = region_first_group_ + uint64_t(region_groups_seen_);
  if (raw) {
    if (raw_size != expected) return invalid(where + ": a group section of the wrong size");
    if (BakeStatus s = writeSection(format::kSectionTensorGroup, id, raw, raw_size); !s) return s;
  } else {
    if (raw_size != expected) return invalid(where + ": a group section of the wrong size");
    const auto t0 = Clock::now();
    const format::ContainerStatus st =
        writer_.addStoredSection(format::kSectionTensorGroup, id, codec, raw_size, stored, stored_size);
    report_.write_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    if (st != format::ContainerStatus::kOk)
      return makeError(ErrorCode::kIo, "cannot write tensor-group section: " + writer_.errorString(st));
  }
  TensorPackLevelReport& lrep = report_.levels.back();
  lrep.error_squared += g.error_squared;
  lrep.norm_squared += g.norm_squared;
  lrep.error_l1 += g.error_l1;
  lrep.data_l1 += g.data_l1;
  ++lrep.groups;
  report_.cp_seconds += g.seconds;
  report_.negative_mass_fraction += g.negative_mass;  // normalised in finish()
  absolute_mass_ += g.absolute_mass;
  const double group_error = g.norm_squared > 0.0 ? std::sqrt(g.error_squared / g.norm_squared) : 0.0;
  report_.max_group_error = std::max(report_.max_group_error, group_error);
  ++report_.rank_histogram[g.rank];
  report_.max_rank = std::max(report_.max_rank, g.rank);
  ++report_.groups;
  ++region_groups_seen_;
  return okStatus();
}

BakeStatus TensorAssembler::endRegion() {
  if (!in_region_ || region_groups_seen_ != region_.group_count)
    return invalid("region " + std::to_string(region_.region) + " of level " + std::to_string(level_) +
                   ": fewer groups than announced");
  in_region_ = false;
  ++next_region_;
  return okStatus();
}

BakeStatus TensorAssembler::endLevel() {
  if (level_ < 0 || in_region_ || next_region_ != int(record_.regions_x * record_.regions_y))
    return invalid("level " + std::to_string(level_) + " ends before its last region");
  if (BakeStatus s = writeSection(format::kSectionTensorIndex, uint64_t(level_), index_.data(),
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
  // NDF images are non-negative, so the level's sum |D| is the sum of its summed image; the
  // dropped blocks' error is their mass, what the kept ones do not hold.
  double mass = 0.0;
  for (double v : level_sum_) mass += v;
  const double dropped_mass = std::max(mass - lrep.data_l1, 0.0);
  lrep.l1_error = mass > 0.0 ? (lrep.error_l1 + dropped_mass) / mass : 0.0;
  std::vector<double>().swap(level_sum_);
  std::vector<format::TensorIndexEntry>().swap(index_);
  return okStatus();
}

BakeStatus TensorAssembler::finish() {
  if (in_region_ || !index_.empty()) return invalid("the last level did not end");
  if (report_.groups == 0) {
    return invalid("every NDF block is blank (block mass below the blank threshold " +
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

}  // namespace glintbake::bake::tensor
