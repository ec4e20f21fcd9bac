// SPDX-License-Identifier: Apache-2.0
// Command scaffolding shared by every tool: parsing, exit codes, reporting, progress, depfiles,
// atomic outputs and the thread limit.
#include <glintbake/cli/embed.h>
#include <glintbake/cli/stdin_input.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>
#include <glintbake/version.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
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
  if (final_path == "-") {  // standard output: the bytes are written on commit()
    to_stdout_ = true;
    return;
  }
  if (file_.open(final_path) != format::ContainerStatus::kOk)
    throw Error(kExitIo, "cannot create " + file_.errorMessage());
  // A named temporary file (no anonymous files on this file system) is removed on signals.
  registered_ = file_.temporaryPath();
  if (!registered_.empty()) registerTemporary(registered_);
}

AtomicOutput::~AtomicOutput() {
  if (to_stdout_) return;
  file_.abort();
  if (!registered_.empty()) unregisterTemporary(registered_);
}

void AtomicOutput::write(const void* data, size_t size) {
  if (to_stdout_) {
    buffered_.append(static_cast<const char*>(data), size);
    return;
  }
  if (file_.write(data, size) != format::ContainerStatus::kOk)
    throw Error(kExitIo, "cannot write " + file_.errorMessage());
}

void AtomicOutput::commit() {
  if (to_stdout_) {
    std::cout.write(buffered_.data(), std::streamsize(buffered_.size()));
    std::cout.flush();
    if (!std::cout) throw Error(kExitIo, "cannot write to standard output");
    return;
  }
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
  for (const auto& d : dependencies)
    if (d != "-") text += " \\\n  " + escapeMake(d);
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

namespace {

// An option's value in plain words: N for integers, X for reals, the choices of a set (8|16), or
// the type name an option gave itself; never CLI11's validator text (INT:INT in [0 - 1024]).
std::string plainTypeName(const CLI::Option* opt) {
  const std::string full = opt->get_type_name();
  const size_t colon = full.find(':');
  const std::string base = full.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : full.substr(colon + 1);
  const bool integer = base == "INT" || base == "UINT";
  if (integer && rest.size() > 2 && rest.front() == '{' && rest.back() == '}' &&
      rest.find_first_not_of("0123456789,-") == 1 && rest.find_first_not_of("0123456789,-", 1) == rest.size() - 1) {
    std::string choices = rest.substr(1, rest.size() - 2);
    for (char& c : choices)
      if (c == ',') c = '|';
    return choices;
  }
  if (integer) return "N";
  if (base == "FLOAT") return "X";
  return base;
}

// Option names without CLI11's flag-value suffixes ("--no-flakes{false}" -> "--no-flakes").
std::string plainOptionName(std::string names) {
  for (size_t open = names.find('{'); open != std::string::npos; open = names.find('{', open)) {
    const size_t close = names.find('}', open);
    if (close == std::string::npos) break;
    names.erase(open, close - open + 1);
  }
  return names;
}

// --help in plain words: value names from plainTypeName, names from plainOptionName.
class PlainFormatter final : public CLI::Formatter {
 public:
  std::string make_option_name(const CLI::Option* opt, bool is_positional) const override {
    return plainOptionName(CLI::Formatter::make_option_name(opt, is_positional));
  }
  std::string make_option_opts(const CLI::Option* opt) const override {
    if (!opt->get_option_text().empty() || opt->get_type_size() == 0) return CLI::Formatter::make_option_opts(opt);
    std::string out;
    const std::string type = plainTypeName(opt);
    if (!type.empty()) out += " " + type;
    if (!opt->get_default_str().empty() && !opt->get_required()) out += "=" + opt->get_default_str();
    if (opt->get_expected_max() == CLI::detail::expected_max_vector_size) out += " ...";
    if (opt->get_required()) out += " REQUIRED";
    return out;
  }
};

}  // namespace

Tool::Tool(std::string name, std::string description) : name_(std::move(name)), app_(description, name_) {
  app_.formatter(std::make_shared<PlainFormatter>());
  app_.set_version_flag("--version", versionString(name_));
  app_.option_defaults()->always_capture_default();
  app_.add_flag("--json", common_.json, "Print a machine-readable summary on stdout (see schemas/)");
  app_.add_flag("-q,--quiet", common_.quiet_level,
                "No progress bar and no informational messages; give it twice (-qq) to hide warnings too");
  app_.add_flag("--strict", common_.strict, "Treat warnings as errors: exit code 6 and no output files");
  // Hidden: prints the man page built from these option definitions (tools/CMakeLists.txt).
  app_.add_flag("--help-man", "Print the manual page (roff) and exit")->group("");
  app_.add_option("-j,--threads", common_.threads,
                  "Worker threads (0 = all cores); output is identical for every value")
      ->check(CLI::Range(0, 1024));
  app_.add_option("--depfile", common_.depfile, "Write a Make-syntax dependency file listing the inputs");
  updateFooter();
}

namespace {
constexpr const char* kExitCodesText =
    "0 ok, 1 bad arguments, 2 I/O error, 3 invalid input, 4 runtime failure, 5 unsupported, "
    "6 warnings under --strict, 7 differences found";

// Levenshtein distance, for "did you mean" suggestions.
size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// roff text with its special characters escaped.
std::string roff(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\\')
      out += "\\e";
    else if (c == '-')
      out += "\\-";
    else
      out += c;
  }
  if (!out.empty() && (out[0] == '.' || out[0] == '\'')) out = "\\&" + out;
  return out;
}

void manOptions(std::string& page, const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->get_group().empty()) continue;  // hidden
    std::string names;
    for (const std::string& s : opt->get_snames()) names += (names.empty() ? "-" : ", -") + s;
    for (const std::string& l : opt->get_lnames()) names += (names.empty() ? "--" : ", --") + l;
    if (names.empty()) names = opt->get_name();  // positional
    page += ".TP\n.B " + roff(names);
    if (opt->get_type_size() != 0 && !plainTypeName(opt).empty()) page += " \\fI" + roff(plainTypeName(opt)) + "\\fR";
    page += "\n" + roff(opt->get_description());
    if (!opt->get_default_str().empty() && opt->get_type_size() != 0)
      page += " (default: " + roff(opt->get_default_str()) + ")";
    page += "\n";
  }
}
}  // namespace

void Tool::addExample(const std::string& command, const std::string& explanation) {
  examples_.emplace_back(command, explanation);
  updateFooter();
}

void Tool::updateFooter() {
  std::string footer;
  if (!examples_.empty()) {
    footer += "Examples:\n";
    for (const auto& [command, explanation] : examples_) footer += "  " + command + "\n      " + explanation + "\n";
    footer += "\n";
  }
  footer += std::string("Exit codes: ") + kExitCodesText + ".";
  app_.footer(footer);
}

std::string Tool::manPage() const {
  std::string upper = name_;
  for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
  std::string page = ".TH " + upper + " 1 \"\" \"glintbake " GLINTBAKE_VERSION_STRING "\" \"glintbake manual\"\n";
  page += ".SH NAME\n" + roff(name_) + " \\- " + roff(app_.get_description()) + "\n";
  page += ".SH SYNOPSIS\n.B " + roff(name_) + "\n";
  const auto subcommands = app_.get_subcommands([](const CLI::App*) { return true; });
  page += subcommands.empty() ? "[\\fIOPTIONS\\fR]\n" : "\\fICOMMAND\\fR [\\fIOPTIONS\\fR]\n";
  page += ".SH OPTIONS\n";
  manOptions(page, app_);
  for (const CLI::App* sub : subcommands) {
    page += ".SH COMMAND " + roff(sub->get_name()) + "\n" + roff(sub->get_description()) + "\n";
    manOptions(page, *sub);
  }
  if (!examples_.empty()) {
    page += ".SH EXAMPLES\n";
    for (const auto& [command, explanation] : examples_)
      page += ".TP\n.B " + roff(command) + "\n" + roff(explanation) + "\n";
  }
  page += ".SH EXIT STATUS\n" + roff(kExitCodesText) + ".\n";
  page +=
      ".SH SEE ALSO\nThe container specification SPEC.md and the JSON schemas installed with glintbake's "
      "documentation.\n";
  return page;
}

// "did you mean --sigma0?" for the first argument that names no option or subcommand.
std::string Tool::suggestion(int argc, char** argv) const {
  std::vector<std::string> names;
  std::vector<const CLI::App*> apps{&app_};
  for (const CLI::App* sub : app_.get_subcommands([](const CLI::App*) { return true; })) {
    apps.push_back(sub);
    names.push_back(sub->get_name());
  }
  for (const CLI::App* a : apps)
    for (const CLI::Option* opt : a->get_options()) {
      for (const std::string& l : opt->get_lnames()) names.push_back("--" + l);
    }
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    const size_t eq = arg.find('=');
    if (arg.rfind("--", 0) == 0 && eq != std::string::npos) arg = arg.substr(0, eq);
    const bool is_option = arg.rfind("--", 0) == 0;
    if (std::find(names.begin(), names.end(), arg) != names.end()) continue;
    if (!is_option && i != 1) continue;  // a value or positional argument
    std::string best;
    size_t best_distance = std::max<size_t>(2, arg.size() / 3) + 1;
    for (const std::string& n : names) {
      if ((n.rfind("--", 0) == 0) != is_option) continue;
      const size_t d = editDistance(arg, n);
      if (d < best_distance) best_distance = d, best = n;
    }
    if (!best.empty()) return "did you mean '" + best + "' for '" + arg + "'?";
  }
  return "";
}

Tool::~Tool() = default;

int Tool::threadCount() const { return common_.threads > 0 ? common_.threads : int(tbb::info::default_concurrency()); }

int Tool::run(int argc, char** argv, const std::function<int(Tool&)>& body) {
  EmbedHooks* hooks = embedHooks();
  if (!hooks) installSignalHandlers();
  const auto fail = [this, hooks](int code, const std::string& message) {
    std::string line = nameStdin(message);
    std::replace(line.begin(), line.end(), '\n', ' ');
    if (hooks) hooks->error = line;
    std::fprintf(stderr, "%s: error: %s\n", name_.c_str(), line.c_str());
    return code;
  };
  // A subcommand's --help also lists the options every command takes, and the tool's examples.
  std::string global = "Options of every " + name_ + " command (before or after the subcommand):\n";
  for (const CLI::Option* opt : app_.get_options()) {
    if (opt->get_group().empty() || opt->get_name() == "--help") continue;
    global += "  " + plainOptionName(opt->get_name(false, true)) + "\n      " + opt->get_description() + "\n";
  }
  for (CLI::App* sub : app_.get_subcommands([](CLI::App*) { return true; }))
    sub->footer(global + "\n" + app_.get_footer());
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--help-man") == 0) {
      std::cout << manPage();
      return kExitOk;
    }
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
      const std::string hint = suggestion(argc, argv);
      return fail(kExitBadArguments, std::string(e.what()) + (hint.empty() ? "" : "; " + hint) + " (see --help)");
    }
    common_.quiet = common_.quiet_level > 0;
    thread_limit_ = std::make_unique<ThreadLimit>(threadCount());
    const int code = body(*this);
    if (code == kExitOk && common_.strict && warning_count_ > 0) {
      // Warnings are errors: nothing the run wrote is kept.
      for (const std::string& path : outputs_) std::remove(path.c_str());
      return fail(kExitWarnings, std::to_string(warning_count_) + " warning(s) under --strict; outputs removed");
    }
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
  ++warning_count_;
  if (common_.quiet_level < 2) std::fprintf(stderr, "%s: warning: %s\n", name_.c_str(), message.c_str());
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
  // Standard input is named "-" in provenance and left out of depfiles (it is no file Make can see).
  inputs_.push_back(!stdinInputPath().empty() && path == stdinInputPath() ? std::string("-") : path);
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
