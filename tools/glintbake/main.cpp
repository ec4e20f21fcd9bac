// SPDX-License-Identifier: Apache-2.0
// glintbake: bakes a manifest of many assets (schemas/glintbake-manifest.schema.json) by running
// the tools beside it as subprocesses: incrementally (content hashes of the inputs, the tool
// version and the options), in parallel across assets under one -j, sharded assets as shards
// plus a merge; or writes the same work as Slurm jobs (--emit slurm).
#include "manifest.h"
#include "run.h"
#include "slurm.h"

#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

namespace {

namespace batch = glintbake::batch;
namespace cli = glintbake::cli;
namespace format = glintbake::format;
namespace fs = std::filesystem;
using cli::Error;
using cli::Json;

struct BakeOptions {
  std::string manifest;
  std::string emit;  // "" or "slurm"
  std::string emit_dir;
  bool force = false;
  int retries = 3;
  int cpus_per_task = 1;
  std::string partition;
};

// A temporary folder for the logs of running steps, removed when it goes out of scope.
class TempDir {
 public:
  TempDir() {
    std::string base = (fs::temp_directory_path() / "glintbake-bake-XXXXXX").string();
    if (!mkdtemp(base.data())) throw Error(cli::kExitIo, "cannot create a temporary folder");
    path_ = base;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

int runBake(cli::Tool& t, const BakeOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (o.manifest == "-")
    throw Error(cli::kExitBadArguments,
                "a manifest cannot be read from standard input ('-'): its relative paths need the manifest's folder");
  batch::Manifest m = batch::readManifest(o.manifest);
  t.addInput(o.manifest);
  for (const batch::Asset& a : m.assets) {
    for (const std::string& in : a.inputs) t.addInput(in);
    t.addOutput(a.output);
  }
  batch::computeKeys(m);
  const auto state = batch::readState(m.state_path);
  std::vector<size_t> stale;
  for (size_t i = 0; i < m.assets.size(); ++i) {
    if (o.force || !batch::upToDate(m.assets[i], state)) stale.push_back(i);
  }

  if (o.emit == "slurm") {
    if (o.emit_dir.empty()) throw Error(cli::kExitBadArguments, "--emit slurm needs --emit-dir DIR");
    batch::SlurmOptions so;
    so.dir = o.emit_dir;
    so.retries = o.retries;
    so.cpus_per_task = o.cpus_per_task;
    so.partition = o.partition;
    const int tasks = batch::emitSlurm(m, stale, so);
    if (t.common().json) {
      Json doc;
      doc["tool"] = "glintbake";
      doc["command"] = "emit-slurm";
      doc["manifest"] = cli::baseName(o.manifest);
      doc["tasks"] = tasks;
      doc["stale"] = stale.size();
      doc["assets"] = m.assets.size();
      t.printJson(doc);
    } else {
      t.info(tasks == 0 ? std::string("every asset is up to date: no job written")
                        : "wrote " + std::to_string(tasks) + " array tasks for " + std::to_string(stale.size()) +
                              " assets into " + o.emit_dir + " (submit with " + o.emit_dir + "/submit.sh)");
    }
    return cli::kExitOk;
  }

  // Every tool single-threaded when several run at once, else all cores for the one.
  const int cores = std::max(1u, std::thread::hardware_concurrency());
  const int jobs = t.threadCount() > 0 ? t.threadCount() : cores;
  const int threads = std::max(1, cores / std::max(1, jobs));
  TempDir logs;
  const std::vector<batch::AssetResult> results = batch::runSteps(m, stale, jobs, threads, logs.path());

  auto new_state = state;
  std::vector<const batch::AssetResult*> by_asset(m.assets.size(), nullptr);
  for (const auto& r : results) by_asset[r.asset] = &r;
  int failed = 0, baked = 0;
  Json assets = Json::array();
  for (size_t i = 0; i < m.assets.size(); ++i) {
    const batch::Asset& a = m.assets[i];
    Json j;
    j["name"] = a.name;
    j["tool"] = a.tool;
    j["output"] = cli::baseName(a.output);
    j["shards"] = a.shards;
    const batch::AssetResult* r = by_asset[i];
    if (!r) {
      j["status"] = "up-to-date";
    } else if (r->failed) {
      ++failed;
      new_state.erase(a.name);
      j["status"] = "failed";
      j["exit_code"] = r->exit_code;
      j["message"] = r->message;
      j["seconds"] = r->seconds;
      t.warning(a.name + ": failed (exit " + std::to_string(r->exit_code) + "): " + r->message);
    } else {
      ++baked;
      std::string hex;
      if (format::hashFile128Hex(a.output, &hex) == format::ContainerStatus::kOk) new_state[a.name] = {a.key, hex};
      j["status"] = "baked";
      j["seconds"] = r->seconds;
      t.info("baked " + a.name + " (" + a.tool + (a.shards > 1 ? ", " + std::to_string(a.shards) + " shards" : "") +
             ") in " + std::to_string(r->seconds) + " s");
    }
    assets.push_back(j);
  }
  // Entries of assets no longer in the manifest are dropped.
  for (auto it = new_state.begin(); it != new_state.end();) {
    const bool known =
        std::any_of(m.assets.begin(), m.assets.end(), [&](const batch::Asset& a) { return a.name == it->first; });
    it = known ? std::next(it) : new_state.erase(it);
  }
  batch::writeState(m.state_path, new_state);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int up_to_date = int(m.assets.size()) - int(stale.size());
  if (t.common().json) {
    Json doc;
    doc["tool"] = "glintbake";
    doc["command"] = "bake";
    doc["manifest"] = cli::baseName(o.manifest);
    doc["assets"] = assets;
    doc["baked"] = baked;
    doc["up_to_date"] = up_to_date;
    doc["failed"] = failed;
    doc["jobs"] = jobs;
    doc["seconds"] = seconds;
    t.printJson(doc);
  } else {
    t.info(std::to_string(baked) + " baked, " + std::to_string(up_to_date) + " up to date, " + std::to_string(failed) +
           " failed in " + std::to_string(seconds) + " s");
  }
  if (failed > 0) {
    // The batch fails; the depfile is still written, so make re-runs what failed.
    t.finishDepfile();
    return cli::kExitRuntime;
  }
  return cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Tool tool("glintbake", "Bakes a manifest of assets with the glintbake tools, here or as Slurm jobs");
  tool.addExample("glintbake bake assets.json -j 8 --json",
                  "Bake every stale asset of a manifest, eight tools at a time.");
  tool.addExample("glintbake bake assets.json --emit slurm --emit-dir farm/",
                  "Write the same work as a Slurm job array and a merge job (farm/submit.sh submits them).");
  CLI::App& app = tool.app();
  app.fallthrough();
  app.require_subcommand(0, 1);
  BakeOptions o;
  CLI::App* bake = app.add_subcommand("bake", "Bakes the stale assets of a manifest (exit 4 when any fails)");
  bake->add_option("manifest", o.manifest, "Manifest (.json, schemas/glintbake-manifest.schema.json)")->required();
  bake->add_option("--emit", o.emit, "Write the work as jobs for a farm instead of running it: slurm")
      ->check(CLI::IsMember({"slurm"}));
  bake->add_option("--emit-dir", o.emit_dir, "With --emit: the folder of the job scripts (created)");
  bake->add_flag("--force", o.force, "Rebake every asset, up to date or not");
  bake->add_option("--retries", o.retries, "With --emit slurm: attempts per array task (1..10)")->capture_default_str();
  bake->add_option("--cpus-per-task", o.cpus_per_task, "With --emit slurm: CPUs of each task (each tool's -j)")
      ->capture_default_str();
  bake->add_option("--partition", o.partition, "With --emit slurm: the Slurm partition");
  return tool.run(argc, argv, [&](cli::Tool& t) {
    if (!bake->parsed()) throw Error(cli::kExitBadArguments, "no command given: use bake (see --help)");
    if (o.retries < 1 || o.retries > 10) throw Error(cli::kExitBadArguments, "--retries must be in [1, 10]");
    if (o.cpus_per_task < 1 || o.cpus_per_task > 1024)
      throw Error(cli::kExitBadArguments, "--cpus-per-task must be in [1, 1024]");
    return runBake(t, o);
  });
}
