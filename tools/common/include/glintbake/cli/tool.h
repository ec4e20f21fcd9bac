// SPDX-License-Identifier: Apache-2.0
// Shared scaffolding of every glintbake command-line tool: exit codes, common options, the
// reporter, progress, depfiles and atomic outputs. Tools are thin main()s over the libraries:
//
//   int main(int argc, char** argv) {
//     glintbake::cli::Tool tool("ndfgen", "Bakes NDF pyramids from normal maps");
//     ... tool.app().add_option(...) ...
//     return tool.run(argc, argv, [&](glintbake::cli::Tool& t) { ...; return glintbake::cli::kExitOk; });
//   }
//
// Errors are reported by throwing glintbake::cli::Error(code, message); run() prints
// "<tool>: error: <message>" as one line on stderr and returns the code.
#pragma once

#include <glintbake/format/atomic_file.h>
#include <glintbake/format/container.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace glintbake::cli {

// Documented exit codes (README.md, "Exit codes"). Stable across versions.
enum ExitCode : int {
  kExitOk = 0,
  kExitBadArguments = 1,  // unknown option, out-of-range parameter, missing argument
  kExitIo = 2,            // a file cannot be read or written
  kExitInvalidInput = 3,  // an input file is malformed, corrupt or holds invalid data (NaN, ...)
  kExitRuntime = 4,       // the computation failed (out of memory, did not converge, ...)
  kExitUnsupported = 5,   // valid input this version does not support (newer container major, ...)
  kExitWarnings = 6,      // --strict: the run gave warnings (its outputs are removed)
  kExitDifferences = 7,   // glintinfo diff / compare found differences beyond tolerance
};

class Error : public std::runtime_error {
 public:
  Error(int code, const std::string& message) : std::runtime_error(message), code_(code) {}
  int code() const { return code_; }

 private:
  int code_;
};

using Json = nlohmann::ordered_json;

// Options every tool has. Filled by CLI11 during parsing.
struct CommonOptions {
  bool json = false;    // --json: machine-readable summary on stdout
  bool quiet = false;   // --quiet: no progress, no informational messages
  int quiet_level = 0;  // how many times -q/--quiet was given: 2 or more also hides warnings
  bool strict = false;  // --strict: warnings are errors (exit code 6)
  int threads = 0;      // -j/--threads: 0 = all cores
  std::string depfile;  // --depfile FILE
};

// Shows a progress bar on stderr only when stderr is a terminal and neither --quiet nor --json.
// Thread-safe: advance() may be called from worker threads.
class Progress {
 public:
  Progress(const std::string& label, uint64_t total, bool enabled);
  ~Progress();
  void advance(uint64_t n = 1);
  void finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// An output file written atomically (format::AtomicFile): write() the bytes, then commit() puts
// the file in place. The path "-" is standard output (the bytes are written on commit()). Nothing is left behind if commit() is not reached, on a failed write (full
// disk, file-size limit) or on SIGINT/SIGTERM/SIGHUP. Failures throw Error(kExitIo) naming the
// path and the reason ("File too large").
class AtomicOutput {
 public:
  explicit AtomicOutput(const std::string& final_path);  // throws Error(kExitIo)
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;
  const std::string& finalPath() const { return final_; }
  void write(const void* data, size_t size);  // throws Error(kExitIo)
  void write(const std::string& bytes) { write(bytes.data(), bytes.size()); }
  void commit();  // throws Error(kExitIo) on failure

 private:
  std::string final_, registered_;
  format::AtomicFile file_;
  bool to_stdout_ = false;  // "-": standard output
  std::string buffered_;
};

// Writes bytes to path through an AtomicOutput (throws Error(kExitIo) on failure).
void writeOutputFile(const std::string& path, const std::string& bytes);

// Registers a path to unlink if the process receives SIGINT/SIGTERM (used by AtomicOutput and by
// format::Writer users through Tool::guardTemporary). Async-signal-safe removal.
void registerTemporary(const std::string& path);
void unregisterTemporary(const std::string& path);

// Writes a Make-syntax depfile "target: dep1 dep2 ...", atomically, escaping spaces and '$'.
void writeDepfile(const std::string& depfile, const std::vector<std::string>& targets,
                  const std::vector<std::string>& dependencies);

class Tool {
 public:
  Tool(std::string name, std::string description);
  ~Tool();

  CLI::App& app() { return app_; }
  const std::string& name() const { return name_; }
  CommonOptions& common() { return common_; }

  // Parses, sets the TBB thread limit, runs body, maps exceptions to exit codes. Never throws.
  int run(int argc, char** argv, const std::function<int(Tool&)>& body);

  // Informational message on stderr (suppressed by --quiet and --json).
  void info(const std::string& message) const;
  // Warning on stderr (printed under --quiet, suppressed by -qq); with --strict the run then
  // fails with kExitWarnings.
  void warning(const std::string& message) const;
  // Example command lines shown at the end of --help and in the man page, each with a sentence.
  void addExample(const std::string& command, const std::string& explanation);
  // Progress bar honouring the terminal check, --quiet and --json.
  std::unique_ptr<Progress> progress(const std::string& label, uint64_t total) const;
  // Prints a JSON document to stdout (indent 2, trailing newline).
  void printJson(const Json& document) const;
  // Records an input file for the depfile and provenance; returns its xxh3-128 content hash.
  std::string addInput(const std::string& path);
  // Records an output file (depfile target).
  void addOutput(const std::string& path);
  // Writes the depfile if --depfile was given. run() calls it after a successful body; tools may
  // call it earlier (it writes once).
  void finishDepfile() const;
  // Container metadata with provenance (schemas/container-metadata.schema.json): tool, version,
  // asset kind, canonical parameters and the name and content hash of every input added so far.
  // Never an absolute path or a timestamp. The asset kind's name comes from the kind registry
  // (glintbake/format/kinds.h); the string form is kept for callers that still pass the name.
  Json makeMetadata(format::AssetKind kind, const Json& parameters) const;
  Json makeMetadata(const std::string& asset_kind, const Json& parameters) const;
  const std::vector<std::string>& inputs() const { return inputs_; }
  // Effective thread count (resolved -j).
  int threadCount() const;

 private:
  std::string name_;
  CLI::App app_;
  CommonOptions common_;
  std::vector<std::string> inputs_, outputs_, input_hashes_;
  std::vector<std::pair<std::string, std::string>> examples_;
  mutable size_t warning_count_ = 0;
  void updateFooter();
  std::string manPage() const;
  std::string suggestion(int argc, char** argv) const;
  std::unique_ptr<struct ThreadLimit> thread_limit_;
  mutable bool depfile_written_ = false;
};

// "glintbake <tool> <version> (container format <major>.<minor>)"
std::string versionString(const std::string& tool);

// Returns the file name component of a path (provenance records names, never absolute paths).
std::string baseName(const std::string& path);

}  // namespace glintbake::cli
