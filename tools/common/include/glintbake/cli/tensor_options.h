// SPDX-License-Identifier: Apache-2.0
// The compression options of the tools that pack NDF pyramids into CP tensors (tensorpack,
// wangtile), with the same names and defaults: --rank, --block, --method, --nonneg, --tol,
// --max-iters, --error-target, --blank-threshold, --precision, --exact-levels, --seed, --zstd-level.
#pragma once

#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/cli/tool.h>

#include <string>

namespace glintbake::cli {

struct TensorCliOptions {
  std::string method_text = "compressed", precision_text = "float32";
  bake::tensor::TensorPackOptions pack;
  double error_target = -1.0;
  double exact_mib = 16.0;
  int zstd_level = 9;
};

// Registers the options (non-negative factors by default); seed_name is the CP seed's option name.
void addTensorPackOptions(CLI::App& app, TensorCliOptions& options, const std::string& seed_name = "--seed");

// Checks the parsed options and derives the library's (Error exit 1 naming the option).
void resolveTensorPackOptions(const CLI::App& app, TensorCliOptions& options);

// Canonical JSON of the options (metadata and --json), in their recorded order.
Json tensorPackOptionsJson(const TensorCliOptions& options);

}  // namespace glintbake::cli
