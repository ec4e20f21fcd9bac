// Command scaffolding shared by every tool: parsing, exit codes, reporting, progress, depfiles,
// atomic outputs and the thread limit.
#include <glintbake/cli/embed.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>
#include <glintbake/version.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <new>

namespace glintbake::cli {

// ---------------------------------------------------------------------------------------------
// Temporary files removed on SIGINT/SIGTERM. The handler may only call async-signal-safe
// functions, so paths live in a fixed table of C strings.
namespace {

constexpr int kMaxTemporaries = 64;
constexpr size_t kMaxPathLength = 4096;
char g_temporaries[kMaxTemporaries][kMaxPathLength];
volatile sig_atomic_t g_temporary_used[kMaxTemporaries];
std::mutex g_temporary_mutex;
bool g_handlers_installed = false;

extern "C" void removeTemporariesAndExit(int signal_number) {
  for (int i = 0; i < kMaxTemporaries; ++i) {
    if (g_temporary_used[i]) unlink(g_temporaries[i]);
  }
  // Re-raise with the default action so the exit status reports the signal.
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

void installSignalHandlers() {
  if (g_handlers_installed) return;
  g_handlers_installed = true;
  std::signal(SIGINT, removeTemporariesAndExit);
  std::signal(SIGTERM, removeTemporariesAndExit);
  std::signal(SIGHUP, removeTemporariesAndExit);
  // A file-size limit (ulimit -f) must fail the write with EFBIG, reported as an I/O error, rather
  // than kill the process with no message.
  std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace

void registerTemporary(const std::string& path) {
  std::lock_guard<std::mutex> lock(g_temporary_mutex);
  installSignalHandlers();
  if (path.size() >= kMaxPathLength) return;
  for (int i = 0; i < kMaxTemporaries; ++i) {
    if (!g_temporary_used[i]) {
      std::memcpy(g_temporaries[i], path.c_str(), path.size() + 1);
      g_temporary_used[i] = 1;
      return;
    }
  }
}

void unregisterTemporary(const std::string& path) {
  std::lock_guard<std::mutex> lock(g_temporary_mutex);
  for (int i = 0; i < kMaxTemporaries; ++i) {
    if (g_temporary_used[i] && path == g_temporaries[i]) {
      g_temporary_used[i] = 0;
      return;
    }
  }
}

// ---------------------------------------------------------------------------------------------
AtomicOutput::AtomicOutput(const std::string& final_path) : final_(final_path) {
  if (file_.open(final_path) != format::ContainerStatus::kOk)
    throw Error(kExitIo, "cannot create " + file_.errorMessage());
  // A named temporary file (no anonymous files on this file system) is removed on signals.
  registered_ = file_.temporaryPath();
  if (!registered_.empty()) registerTemporary(registered_);
}

AtomicOutput::~AtomicOutput() {
  file_.abort();
  if (!registered_.empty()) unregisterTemporary(registered_);
}

void AtomicOutput::write(const void* data, size_t size) {
  if (file_.write(data, size) != format::ContainerStatus::kOk)
    throw Error(kExitIo, "cannot write " + file_.errorMessage());
}

void AtomicOutput::commit() {
  if (file_.commit() != format::ContainerStatus::kOk) throw Error(kExitIo, "cannot write " + file_.errorMessage());
}

void writeOutputFile(const std::string& path, const std::string& bytes) {
  AtomicOutput out(path);
  out.write(bytes);
  out.commit();
}

// ---------------------------------------------------------------------------------------------
namespace {

std::string escapeMake(const std::string& path) {
  std::string out;
  for (char c : path) {
    if (c == ' ' || c == '#') out += '\\';
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

}  // namespace

void writeDepfile(const std::string& depfile, const std::vector<std::string>& targets,
                  const std::vector<std::string>& dependencies) {
  std::string text;
  for (size_t i = 0; i < targets.size(); ++i) text += (i ? " " : "") + escapeMake(targets[i]);
  text += ":";
  for (const auto& d : dependencies) text += " \\\n  " + escapeMake(d);
  text += "\n";
  writeOutputFile(depfile, text);
}

// ---------------------------------------------------------------------------------------------
// The hooks of an embedded run (embed.h), guarded so that one embedded run is active at a time.
std::mutex g_embed_mutex;
std::atomic<EmbedHooks*> g_embed_hooks{nullptr};

EmbedScope::EmbedScope(EmbedHooks* hooks) {
  g_embed_mutex.lock();
  g_embed_hooks.store(hooks);
}

EmbedScope::~EmbedScope() {
  g_embed_hooks.store(nullptr);
  g_embed_mutex.unlock();
}

EmbedHooks* embedHooks() { return g_embed_hooks.load(); }

const std::atomic<bool>* cancelFlag() {
  const EmbedHooks* hooks = embedHooks();
  return hooks ? hooks->cancel : nullptr;
}

struct Progress::Impl {
  std::string label;
  EmbedHooks* hooks = nullptr;  // embedded: report to the host instead of drawing
  std::chrono::steady_clock::time_point last_report;
  uint64_t total = 0;
  std::atomic<uint64_t> done{0};
  bool enabled = false;
  std::mutex mutex;
  std::chrono::steady_clock::time_point start, last_draw;
  bool finished = false;

  void draw(bool final_line) {
    const uint64_t d = std::min(done.load(), total);
    const double fraction = total ? double(d) / double(total) : 1.0;
    const int width = 30;
    const int filled = int(fraction * width + 0.5);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "\r%-16s [%.*s%*s] %5.1f%% %6.1fs", label.c_str(), filled, "##############################",
                 width - filled, "", fraction * 100.0, elapsed);
    if (final_line) std::fputc('\n', stderr);
    std::fflush(stderr);
  }
};

Progress::Progress(const std::string& label, uint64_t total, bool enabled) : impl_(new Impl) {
  impl_->label = label;
  impl_->total = total;
  impl_->enabled = enabled;
  impl_->start = impl_->last_draw = impl_->last_report = std::chrono::steady_clock::now();
  EmbedHooks* hooks = embedHooks();
  if (hooks && hooks->progress) impl_->hooks = hooks;
}

Progress::~Progress() { finish(); }

void Progress::advance(uint64_t n) {
  impl_->done += n;
  if (impl_->hooks) {
    std::unique_lock<std::mutex> lock(impl_->mutex, std::try_to_lock);
    if (!lock.owns_lock() || impl_->finished) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - impl_->last_report < std::chrono::milliseconds(50)) return;
    impl_->last_report = now;
    impl_->hooks->progress(impl_->label, std::min(impl_->done.load(), impl_->total), impl_->total);
    return;
  }
  if (!impl_->enabled) return;
  std::unique_lock<std::mutex> lock(impl_->mutex, std::try_to_lock);
  if (!lock.owns_lock() || impl_->finished) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - impl_->last_draw < std::chrono::milliseconds(100)) return;
  impl_->last_draw = now;
  impl_->draw(false);
}

void Progress::finish() {
  if (impl_ && impl_->hooks) {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    if (impl_->finished) return;
    impl_->finished = true;
    impl_->hooks->progress(impl_->label, std::min(impl_->done.load(), impl_->total), impl_->total);
    return;
  }
  if (!impl_ || !impl_->enabled) return;
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->finished) return;
  impl_->finished = true;
  impl_->draw(true);
}

// ---------------------------------------------------------------------------------------------
struct ThreadLimit {
  explicit ThreadLimit(int n) : control(tbb::global_control::max_allowed_parallelism, size_t(n)) {}
  tbb::global_control control;
};

std::string versionString(const std::string& tool) {
  return "glintbake " + tool + " " GLINTBAKE_VERSION_STRING " (container format " +
         std::to_string(format::kFormatVersionMajor) + "." + std::to_string(format::kFormatVersionMinor) + ")";
}

std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

Tool::Tool(std::string name, std::string description) : name_(std::move(name)), app_(description, name_) {
  app_.set_version_flag("--version", versionString(name_));
  app_.option_defaults()->always_capture_default();
  app_.add_flag("--json", common_.json, "Print a machine-readable summary on stdout (see schemas/)");
  app_.add_flag("-q,--quiet", common_.quiet, "No progress bar and no informational messages");
  app_.add_option("-j,--threads", common_.threads,
                  "Worker threads (0 = all cores); output is identical for every value")
      ->check(CLI::Range(0, 1024));
  app_.add_option("--depfile", common_.depfile, "Write a Make-syntax dependency file listing the inputs");
  app_.footer(
      "Exit codes: 0 ok, 1 bad arguments, 2 I/O error, 3 invalid input, 4 runtime failure,\n"
      "5 unsupported, 7 differences found.");
}

Tool::~Tool() = default;

int Tool::threadCount() const { return common_.threads > 0 ? common_.threads : int(tbb::info::default_concurrency()); }

int Tool::run(int argc, char** argv, const std::function<int(Tool&)>& body) {
  EmbedHooks* hooks = embedHooks();
  if (!hooks) installSignalHandlers();
  const auto fail = [this, hooks](int code, const std::string& message) {
    std::string line = message;
    std::replace(line.begin(), line.end(), '\n', ' ');
    if (hooks) hooks->error = line;
    std::fprintf(stderr, "%s: error: %s\n", name_.c_str(), line.c_str());
    return code;
  };
  try {
    try {
      app_.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
      std::cout << app_.help();
      return kExitOk;
    } catch (const CLI::CallForAllHelp&) {
      std::cout << app_.help("", CLI::AppFormatMode::All);
      return kExitOk;
    } catch (const CLI::CallForVersion&) {
      std::cout << versionString(name_) << "\n";
      return kExitOk;
    } catch (const CLI::ParseError& e) {
      return fail(kExitBadArguments, std::string(e.what()) + " (see --help)");
    }
    thread_limit_ = std::make_unique<ThreadLimit>(threadCount());
    const int code = body(*this);
    if (code == kExitOk) finishDepfile();
    std::cout.flush();
    return code;
  } catch (const Error& e) {
    return fail(e.code(), e.what());
  } catch (const std::bad_alloc&) {
    return fail(kExitRuntime, "out of memory");
  } catch (const std::exception& e) {
    return fail(kExitRuntime, e.what());
  } catch (...) {
    return fail(kExitRuntime, "unknown failure");
  }
}

void Tool::info(const std::string& message) const {
  if (!common_.quiet && !common_.json) std::fprintf(stderr, "%s: %s\n", name_.c_str(), message.c_str());
}

void Tool::warning(const std::string& message) const {
  if (!common_.quiet) std::fprintf(stderr, "%s: warning: %s\n", name_.c_str(), message.c_str());
}

std::unique_ptr<Progress> Tool::progress(const std::string& label, uint64_t total) const {
  const bool enabled = !common_.quiet && !common_.json && isatty(STDERR_FILENO);
  return std::make_unique<Progress>(label, total, enabled);
}

void Tool::printJson(const Json& document) const {
  if (EmbedHooks* hooks = embedHooks()) {
    hooks->json = document;
    return;
  }
  std::cout << document.dump(2) << "\n";
}

std::string Tool::addInput(const std::string& path) {
  std::string hex;
  const format::ContainerStatus status = format::hashFile128Hex(path, &hex);
  if (status != format::ContainerStatus::kOk) {
    throw Error(kExitIo, "cannot read " + path + ": " + (errno ? std::strerror(errno) : format::statusString(status)));
  }
  inputs_.push_back(path);
  input_hashes_.push_back(hex);
  return hex;
}

void Tool::addOutput(const std::string& path) { outputs_.push_back(path); }

void Tool::finishDepfile() const {
  if (common_.depfile.empty() || depfile_written_) return;
  if (outputs_.empty()) {
    warning("--depfile ignored: this command writes no output file");
  } else {
    try {
      writeDepfile(common_.depfile, outputs_, inputs_);
    } catch (const Error&) {
      // Make must not see a fresh output without its dependencies: it would never rebuild it.
      for (const auto& output : outputs_) std::remove(output.c_str());
      throw;
    }
  }
  depfile_written_ = true;
}

Json Tool::makeMetadata(format::AssetKind kind, const Json& parameters) const {
  return makeMetadata(std::string(format::assetKindString(kind)), parameters);
}

Json Tool::makeMetadata(const std::string& asset_kind, const Json& parameters) const {
  Json meta;
  meta["schema"] = "glintbake.container-metadata/1";
  meta["asset_kind"] = asset_kind;
  meta["generator"] = {{"tool", name_}, {"version", GLINTBAKE_VERSION_STRING}};
  meta["parameters"] = parameters;
  Json inputs = Json::array();
  for (size_t i = 0; i < inputs_.size(); ++i) {
    inputs.push_back({{"name", baseName(inputs_[i])}, {"hash", input_hashes_[i]}});
  }
  meta["inputs"] = inputs;
  return meta;
}

}  // namespace glintbake::cli
