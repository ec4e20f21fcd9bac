// SPDX-License-Identifier: Apache-2.0
// glintbake bake --emit slurm: the stale assets of a manifest as Slurm jobs (README, "Studio scale").
#pragma once

#include "manifest.h"

#include <string>
#include <vector>

namespace glintbake::batch {

struct SlurmOptions {
  std::string dir;        // where the scripts go (created)
  int retries = 3;        // attempts per task
  int cpus_per_task = 1;  // --cpus-per-task and each tool's -j
  std::string partition;  // empty: the cluster's default
};

// Writes into options.dir: tasks.txt (one shell command per array task: an asset's bake or one
// shard), bake.sbatch (the job array: runs its line, retrying failed attempts, one log per task
// under logs/), merge.sbatch (the merges, after every task succeeded), submit.sh (submits both,
// the merge job dependent on the array). Returns the number of array tasks (0: nothing to bake,
// no job). Throws cli::Error exit 2 when the files cannot be written.
int emitSlurm(const Manifest& manifest, const std::vector<size_t>& stale, const SlurmOptions& options);

}  // namespace glintbake::batch
