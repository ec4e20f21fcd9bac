// SPDX-License-Identifier: Apache-2.0
// The tensor-ndf record checks (formats/SPEC.md 10.4).
#include <glintbake/format/kinds/tensor_ndf.h>

#include <cmath>

namespace glintbake::format {

RecordCheck checkTensorInfoRecord(const TensorInfoRecord& info) {
  if (info.magic != TensorInfoRecord().magic) return {RecordStatus::kBadMagic, "bad magic"};
  if (info.version != 1) return {RecordStatus::kUnsupportedVersion, "unsupported version"};
  if (info.ndf_res < 2 || info.ndf_res > kMaxNdfResolution) return recordInvalid("NDF resolution out of range");
  if (info.block < 1 || info.block > kTensorMaxBlockBins || info.ndf_res % info.block != 0 ||
      info.blocks_per_side != info.ndf_res / info.block)
    return recordInvalid("block size inconsistent with the NDF resolution");
  if (info.level_count < 1 || info.level_count > uint32_t(kMaxNdfLevels))
    return recordInvalid("level count out of range");
  if (info.max_rank < 1 || info.max_rank > kTensorMaxRank) return recordInvalid("rank out of range");
  if (info.precision > 1) return recordInvalid("unknown precision");
  if ((info.flags & ~kTensorFlagNonNegative) != 0) return recordInvalid("unknown flags");
  if (!std::isfinite(info.blank_threshold)) return recordInvalid("non-finite blank threshold");
  return recordOk();
}

RecordCheck checkTensorLevelRecord(const NdfLevelRecord& record, uint32_t key, const TensorInfoRecord& info,
                                   const NdfLevelRecord* below) {
  if (RecordCheck c = checkNdfLevelRecord(record, key, below); !c) return c;
  if (record.ndf_res != info.ndf_res) return recordInvalid("NDF resolution differs from the tensor info");
  return recordOk();
}

RecordCheck checkTensorGroupHeader(const TensorGroupHeader& h, const TensorInfoRecord& info,
                                   const NdfLevelRecord* levels) {
  if (h.magic != TensorGroupHeader().magic) return {RecordStatus::kBadMagic, "bad magic"};
  if (h.bins != info.block || h.rank < 1 || h.rank > info.max_rank || h.blocks < 1 || h.level >= info.level_count ||
      h.precision != info.precision || h.reserved != 0)
    return recordInvalid("group header disagrees with the tensor info");
  const NdfLevelRecord& level = levels[h.level];
  if (uint64_t(h.region) >= uint64_t(level.regions_x) * level.regions_y)
    return recordInvalid("group region outside its level");
  // A group holds the blocks of at most region_size^2 centres.
  const uint64_t nb2 = uint64_t(info.blocks_per_side) * info.blocks_per_side;
  if (uint64_t(h.blocks) > uint64_t(level.region_size) * level.region_size * nb2)
    return recordInvalid("group holds more blocks than its region");
  return recordOk();
}

}  // namespace glintbake::format
