// SPDX-License-Identifier: Apache-2.0
// glintbake bake, run here: the steps of every stale asset on a pool of -j workers, each a tool
// subprocess; an asset's shards before its merge; a failing step fails its asset only.
#include "run.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace glintbake::batch {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Runs argv with stdout discarded and stderr into log; returns the exit code (128 + signal when
// killed, 127 when it cannot start).
int runProcess(const std::vector<std::string>& argv, const std::string& log) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return 127;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 127;
}

// The last non-empty line of a log, without the tool's "error: " prefix noise kept as is.
std::string lastLine(const std::string& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last;
}

}  // namespace

std::vector<AssetResult> runSteps(const Manifest& m, const std::vector<size_t>& stale, int jobs, int threads,
                                  const std::string& log_dir) {
  struct Pending {
    Step step;
    size_t result = 0;
  };
  std::vector<AssetResult> results(stale.size());
  std::vector<std::vector<Pending>> queues(stale.size());  // per asset: its shards (or bake), then its merge
  std::vector<int> running(stale.size(), 0), remaining(stale.size(), 0);
  std::vector<Clock::time_point> started(stale.size());
  std::vector<bool> begun(stale.size(), false);
  for (size_t r = 0; r < stale.size(); ++r) {
    results[r].asset = stale[r];
    for (Step& s : stepsOf(m, stale[r], threads)) queues[r].push_back({s, r});
    remaining[r] = int(queues[r].size());
    if (m.assets[stale[r]].shards > 1) fs::create_directories(partsDir(m.assets[stale[r]]));
  }
  std::mutex mu;
  std::condition_variable cv;
  size_t next_log = 0;

  // The next runnable step: a merge only once its shards are done; assets in manifest order.
  auto take = [&](Pending* out) -> bool {
    for (size_t r = 0; r < queues.size(); ++r) {
      auto& q = queues[r];
      if (q.empty()) continue;
      if (results[r].failed) {  // the rest of a failed asset is dropped
        remaining[r] -= int(q.size());
        q.clear();
        continue;
      }
      if (q.front().step.merge && running[r] > 0) continue;
      *out = q.front();
      q.erase(q.begin());
      if (!begun[r]) started[r] = Clock::now();
      begun[r] = true;
      ++running[r];
      return true;
    }
    return false;
  };
  auto allDone = [&] {
    for (auto& q : queues) {
      if (!q.empty()) return false;
    }
    return true;
  };

  auto worker = [&] {
    std::unique_lock<std::mutex> lock(mu);
    for (;;) {
      Pending p;
      while (!take(&p)) {
        bool idle = true;
        for (int n : running) idle = idle && n == 0;
        if (allDone() && idle) {
          cv.notify_all();
          return;
        }
        cv.wait(lock);
      }
      const std::string log = (fs::path(log_dir) / ("step-" + std::to_string(next_log++) + ".log")).string();
      lock.unlock();
      const int code = runProcess(p.step.argv, log);
      const std::string message = code == 0 ? std::string() : lastLine(log);
      std::remove(log.c_str());
      lock.lock();
      const size_t r = p.result;
      --running[r];
      --remaining[r];
      AssetResult& res = results[r];
      if (code != 0 && !res.failed) {
        res.failed = true;
        res.exit_code = code;
        res.message = message.empty() ? "exit " + std::to_string(code) : message;
        if (p.step.shard >= 0) res.message = "shard " + std::to_string(p.step.shard) + ": " + res.message;
      }
      if (remaining[r] == 0 || (res.failed && running[r] == 0)) {
        res.seconds = std::chrono::duration<double>(Clock::now() - started[r]).count();
        const Asset& a = m.assets[res.asset];
        if (a.shards > 1) {
          std::error_code ec;
          fs::remove_all(partsDir(a), ec);  // the parts, merged or not
        }
        if (res.failed) {
          std::error_code ec;
          fs::remove(a.output, ec);  // a failed asset leaves no output
        }
      }
      cv.notify_all();
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < std::max(1, jobs); ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  return results;
}

}  // namespace glintbake::batch
