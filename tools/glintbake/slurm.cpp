// SPDX-License-Identifier: Apache-2.0
#include "slurm.h"

#include <filesystem>
#include <fstream>

#include <sys/stat.h>

namespace glintbake::batch {
namespace {

namespace fs = std::filesystem;

void writeFile(const fs::path& path, const std::string& text, bool executable) {
  cli::AtomicOutput out(path.string());
  out.write(text.data(), text.size());
  out.commit();
  if (executable) chmod(path.c_str(), 0755);
}

std::string quote(const std::string& s) { return shellQuote({s}); }

}  // namespace

int emitSlurm(const Manifest& m, const std::vector<size_t>& stale, const SlurmOptions& o) {
  std::error_code ec;
  const fs::path dir = fs::absolute(o.dir);
  fs::create_directories(dir / "logs", ec);
  if (ec) throw cli::Error(cli::kExitIo, "cannot create " + o.dir + ": " + ec.message());
  std::string tasks, merges;
  int count = 0;
  for (size_t index : stale) {
    const Asset& a = m.assets[index];
    for (const Step& s : stepsOf(m, index, o.cpus_per_task)) {
      const std::vector<std::string>& argv = s.argv;  // every path absolute (readManifest)
      if (s.merge) {
        merges += shellQuote(argv) + " && rm -rf " + quote(fs::absolute(partsDir(a)).string()) + "\n";
        continue;
      }
      std::string line;
      if (a.shards > 1) line = "mkdir -p " + quote(fs::absolute(partsDir(a)).string()) + " && ";
      tasks += line + shellQuote(argv) + "\n";
      ++count;
    }
  }
  if (count == 0) return 0;
  const std::string d = dir.string();
  std::string header = "#!/bin/bash\n";
  const std::string partition = o.partition.empty() ? "" : "#SBATCH --partition=" + o.partition + "\n";
  std::string bake = header +
                     "# One array task per asset or shard of glintbake bake " + fs::path(m.path).filename().string() +
                     ": runs line SLURM_ARRAY_TASK_ID + 1 of tasks.txt,\n"
                     "# retrying a failed attempt (a killed or preempted tool) up to " +
                     std::to_string(o.retries) +
                     " times; bad arguments (exit 1) and bad input (exit 3) are not retried.\n"
                     "#SBATCH --job-name=glintbake-bake\n"
                     "#SBATCH --array=0-" +
                     std::to_string(count - 1) + "\n" + partition +
                     "#SBATCH --cpus-per-task=" + std::to_string(o.cpus_per_task) +
                     "\n"
                     "#SBATCH --requeue\n"
                     "#SBATCH --output=" +
                     d + "/logs/task-%a.log\n" + "set -u\n" + "line=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" " +
                     quote(d + "/tasks.txt") + ")\n" + "code=0\n" + "for attempt in $(seq 1 " +
                     std::to_string(o.retries) +
                     "); do\n"
                     "  bash -c \"$line\" && exit 0\n"
                     "  code=$?\n"
                     "  echo \"glintbake: task $SLURM_ARRAY_TASK_ID attempt $attempt failed (exit $code)\" >&2\n"
                     "  if [ \"$code\" -eq 1 ] || [ \"$code\" -eq 3 ]; then exit \"$code\"; fi\n"
                     "done\n"
                     "exit \"$code\"\n";
  std::string merge = header +
                      "# The merges of the sharded assets, once every array task succeeded.\n"
                      "#SBATCH --job-name=glintbake-merge\n" +
                      partition + "#SBATCH --output=" + d + "/logs/merge.log\n" + "set -eu\n" +
                      (merges.empty() ? std::string("true\n") : merges);
  std::string submit = header +
                       "# Submits the bake array and the merge job that waits for it; prints both job ids.\n"
                       "set -eu\n"
                       "cd " +
                       quote(d) +
                       "\n"
                       "array=$(sbatch --parsable bake.sbatch)\n"
                       "merge=$(sbatch --parsable --dependency=afterok:${array%%;*} --kill-on-invalid-dep=yes "
                       "merge.sbatch)\n"
                       "echo \"$array $merge\"\n";
  writeFile(dir / "tasks.txt", tasks, false);
  writeFile(dir / "bake.sbatch", bake, true);
  writeFile(dir / "merge.sbatch", merge, true);
  writeFile(dir / "submit.sh", submit, true);
  return count;
}

}  // namespace glintbake::batch
