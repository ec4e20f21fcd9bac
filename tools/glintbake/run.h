// SPDX-License-Identifier: Apache-2.0
// Running the stale assets of a manifest here (glintbake bake without --emit).
#pragma once

#include "manifest.h"

#include <string>
#include <vector>

namespace glintbake::batch {

struct AssetResult {
  size_t asset = 0;
  bool failed = false;
  int exit_code = 0;     // of the first failing step: the tool's exit code, or 128 + signal
  std::string message;   // its last line on stderr
  double seconds = 0.0;  // wall time of the asset's steps
};

// Runs the steps of the assets `stale` (indices into manifest.assets) on `jobs` workers, each tool
// with -j `threads`; logs of running steps go to log_dir. Returns one result per stale asset.
std::vector<AssetResult> runSteps(const Manifest& manifest, const std::vector<size_t>& stale, int jobs, int threads,
                                  const std::string& log_dir);

}  // namespace glintbake::batch
