// SPDX-License-Identifier: Apache-2.0
// Running a tool inside another program (the Python module): the tool parses the same options
// with the same CLI11 definitions as on the command line, and its progress, cancellation, error
// text and --json summary go to the host instead of the terminal.
//
//   cli::EmbedHooks hooks;
//   hooks.progress = [](const std::string& label, uint64_t done, uint64_t total) { ... };
//   hooks.cancel = &flag;
//   int code;
//   { cli::EmbedScope scope(&hooks); code = cli::ndfgenMain(argc, argv); }
//   // hooks.error holds the error line when code != 0, hooks.json the --json document.
#pragma once

#include <glintbake/cli/tool.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

namespace glintbake::cli {

struct EmbedHooks {
  // Progress of the tool's bars (label, done, total): called from any thread, at most every 50 ms
  // per bar and once when a bar finishes. May be empty.
  std::function<void(const std::string& label, uint64_t done, uint64_t total)> progress;
  // Set by the host to stop the computation early: the tool then fails with exit code 4
  // ("cancelled"). May be null.
  const std::atomic<bool>* cancel = nullptr;
  // Filled by the tool: the error message of a failed run (without the "<tool>: error: " prefix),
  // and the document it would have printed with --json (null when it printed none).
  std::string error;
  Json json;
};

// Makes `hooks` the active hooks for the lifetime of the scope. One embedded run at a time in a
// process: a second scope waits until the first ends. While active, tools do not install their
// signal handlers and do not print their --json document.
class EmbedScope {
 public:
  explicit EmbedScope(EmbedHooks* hooks);
  ~EmbedScope();
  EmbedScope(const EmbedScope&) = delete;
  EmbedScope& operator=(const EmbedScope&) = delete;
};

// The active hooks, or null when the tool runs as a program.
EmbedHooks* embedHooks();
// The cancellation flag to hand to the baking library (null when not embedded or none given).
const std::atomic<bool>* cancelFlag();

// The tools' entry points, what their main() calls (tools/<tool>/entry.cpp).
int ndfgenMain(int argc, char** argv);
int tensorpackMain(int argc, char** argv);
int ltcfitMain(int argc, char** argv);

}  // namespace glintbake::cli
