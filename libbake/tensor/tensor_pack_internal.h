// SPDX-License-Identifier: Apache-2.0
// Private pieces of the tensor-ndf packer (bake/tensor/tensor_pack.h): the compression and
// encoding of one group, and the streaming sink that cuts regions into groups.
#pragma once

#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_assembly.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/kinds/tensor_ndf.h>

#include <tbb/task_group.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

namespace glintbake::bake::tensor::detail {

// One group compressed and serialised as a tensor-group section.
struct EncodedGroup {
  std::vector<uint8_t> section;  // TensorGroupHeader, factors, prefix sums (SPEC 10.4)
  int rank = 0;
  double error_squared = 0.0;  // |T - stored model|_F^2 (the model of the stored, rounded factors)
  double norm_squared = 0.0;   // |T|_F^2
  double negative_mass = 0.0;  // sum of max(0, -model) over the group's bins
  double absolute_mass = 0.0;  // sum of |model|
  double error_l1 = 0.0;       // sum of |T - stored model|
  double data_l1 = 0.0;        // sum of |T|
  double seconds = 0.0;        // time of decomposition and encoding
};

// Decomposes `tensor` (fixed rank or error-target mode), rebalances the columns, rounds them to the
// storage precision, builds the prefix sums of the stored values and measures the error of the
// stored model. Reentrant; sequential (one TBB task per group).
Result<EncodedGroup> compressGroup(const GroupTensor& tensor, int level, int region, const TensorPackOptions& options);
// One block stored exactly as a group of rank B: A the identity, B the block's bins, C one
// (tensor.blocks == 1, B <= kTensorMaxRank). The stored model equals the block to the storage
// precision.
Result<EncodedGroup> exactGroup(const GroupTensor& tensor, int level, int region, const TensorPackOptions& options);

// Bytes of a tensor-group section.
size_t groupSectionBytes(int bins, int rank, int blocks, int precision);

// The PyramidSink that turns regions into groups: extracts the non-blank blocks of each chunk,
// compresses them on the TBB pool and hands every region's results, in region order, to a
// TensorRegionConsumer (the asset's TensorAssembler, or a shard's recorder). All methods run on
// the producer's thread.
class TensorPackSink final : public ndf::PyramidSink {
 public:
  TensorPackSink(TensorRegionConsumer& consumer, const TensorPackOptions& options, TensorPackReport& report,
                 const std::atomic<bool>* cancel, const format::Writer* writer = nullptr);
  ~TensorPackSink() override;

  BakeStatus addLevel(const format::NdfLevelRecord& record) override;
  BakeStatus addChunk(const ndf::PyramidChunk& chunk) override;
  BakeStatus skipChunk(int level, int region) override;
  BakeStatus endLevel(int level) override;
  uint64_t storedBytes() const override { return writer_ ? writer_->bytesWritten() : 0; }

  // Checks that every region went to the consumer.
  BakeStatus finish();
  // Time spent inside this sink (the rest of the producer's time made NDF images).
  double secondsInside() const { return seconds_inside_; }

 private:
  // One region: its summary, and its kept blocks (one compressed group, or one exact group each).
  struct Pending {
    bool skipped = false;
    RegionSummary summary;
    std::vector<double> image_sum;
    std::vector<format::TensorIndexEntry> index;
    GroupTensor tensor;
    bool exact = false;
    std::optional<Result<EncodedGroup>> result;
    tbb::task_group task;
  };

  BakeStatus writeFront();  // waits for the oldest pending region and hands it to the consumer
  BakeStatus push(std::unique_ptr<Pending> p);

  TensorRegionConsumer& consumer_;
  const format::Writer* writer_;
  TensorPackOptions options_;
  TensorPackReport& report_;
  const std::atomic<bool>* cancel_;
  size_t max_in_flight_ = 2;

  int ndf_res_ = 0;
  int blocks_per_side_ = 0;
  int level_ = -1;
  bool exact_level_ = false;  // the current level's blocks are stored exactly, one group each
  int grid_width_ = 0;
  std::deque<std::unique_ptr<Pending>> pending_;
  double seconds_inside_ = 0.0;
};

}  // namespace glintbake::bake::tensor::detail
