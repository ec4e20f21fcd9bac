// SPDX-License-Identifier: Apache-2.0
// The end of a tensor-ndf bake, shared by tensorpack and the merge of its shards (glintinfo merge),
// so that both write the same bytes: the flakes hand-over chosen from the levels' errors, the
// quality gate (--max-error) and warnings, the flakes section and the asset's metadata.
#pragma once

#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>

#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::cli {

// The error a gate compares: that of the compressed levels that answer footprints (README,
// "tensorpack defaults").
struct GatedError {
  double error = 0.0;
  double from_sigma = 0.0;  // sigma of the first level gated
  bool whole = true;        // every level answers
};

// What the end of the bake needs besides the packer's report.
struct TensorAssetEnd {
  int lobes_per_tile = 0;      // of the clustered lobes (0: none)
  double max_error = -1.0;     // --max-error (< 0: no gate)
  double error_target = -1.0;  // --error-target (< 0: unset)
  int rank = 16;               // --rank, for the warnings
  std::string label;           // names the input in messages
};

struct TensorAssetResult {
  bake::ndf::FlakesHandover handover;
  GatedError gated;
  std::vector<std::string> warnings;
  uint64_t flake_bytes = 0;                      // raw size of the flakes section written (0: none)
  std::vector<bake::ndf::HandoverProbe> probes;  // the hand-over's probes above exact levels, in order
  Json metadata;                                 // the asset's metadata, complete
};

// Chooses the hand-over, applies the gate (Error exit 4 naming the achieved error, before anything
// else is written), writes `flakes` (the raw flakes section, any hand-over in its record; empty or
// null: no flakes section) with the chosen hand-over, and completes `metadata` (every field that
// does not depend on the compression; tensorpack's metadataTemplate) with the report's levels,
// groups, ranks, error and the flakes. The caller adds the metadata and finishes the writer.
TensorAssetResult finishTensorAsset(format::Writer& writer, const bake::tensor::TensorPackReport& report,
                                    std::vector<uint8_t>* flakes, const Json& metadata, const TensorAssetEnd& end);

// What the merge of a sharded tensorpack bake needs to replay the final assembly, recorded in
// every partial (the shard description's `assembly`): the packer's storage options, the end's
// options and whether the bake has a flakes section.
Json tensorShardAssembly(const bake::tensor::TensorPackOptions& pack, const TensorAssetEnd& end, bool flakes);
// Reads it back (Error exit 3 naming the field when absent or malformed). end.label stays empty.
void readTensorShardAssembly(const Json& assembly, bake::tensor::TensorPackOptions* pack, TensorAssetEnd* end,
                             bool* flakes);

// The hand-over a compressed pyramid calls for: the pyramid answers from the first level from
// which every level is faithful (stored exactly, or compressed within a Frobenius error of 0.15
// and a quarter of the level's variation and within a mean L1 error of 0.06 of its images), the
// clustered lobes below (bake::ndf::compressedHandover).
// With the map's flakes (texels, rate, sigma_r; may be null) a first faithful level stored exactly
// hands over as bake::ndf::probeExactLevelHandover measures, *probes (may be null) receiving what
// it measured, level by level; without them as an exact level whose blend is faithful.
bake::ndf::FlakesHandover tensorHandover(const bake::tensor::TensorPackReport& report, int lobes_per_tile,
                                         const runtime::TexelSource* texels = nullptr, int rate = 1,
                                         double sigma_r = 0.0, std::vector<bake::ndf::HandoverProbe>* probes = nullptr);

// The gated error and its one-line description (tensorpack's --json and messages).
GatedError gatedError(const bake::tensor::TensorPackReport& report, const bake::ndf::FlakesHandover& handover);
std::string achievedText(const bake::tensor::TensorPackReport& report, const GatedError& gated);
// The report's rank histogram as {"rank": groups}.
Json rankHistogramJson(const bake::tensor::TensorPackReport& report);

}  // namespace glintbake::cli
