// SPDX-License-Identifier: Apache-2.0
#include "manifest.h"

#include <glintbake/format/container.h>
#include <glintbake/format/json_depth.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

namespace glintbake::batch {
namespace {

namespace fs = std::filesystem;
using cli::Error;
using cli::Json;

Error malformed(const std::string& where, const std::string& what) {
  return Error(cli::kExitInvalidInput, where + ": " + what);
}

// Tools the manifest may name, and the ones that take --shard.
const std::set<std::string> kTools = {"ndfgen", "tensorpack", "mapgen", "ltcfit", "wangtile", "tinyexample"};
const std::set<std::string> kShardedTools = {"ndfgen", "tensorpack", "wangtile"};
// Options glintbake sets itself.
const std::set<std::string> kReserved = {"o", "output", "shard", "json", "quiet", "depfile", "j", "threads"};

// Absolute, so that the commands run from anywhere (a farm node's working directory included).
std::string resolve(const std::string& dir, const std::string& p) {
  if (p.empty()) return p;
  return fs::absolute(fs::path(dir) / p).lexically_normal().string();
}

// The option object as command-line words, in key order: true -> --k, false -> --no-k,
// numbers and strings -> --k VALUE, arrays -> --k V per element.
std::vector<std::string> optionWords(const Json& options, const std::string& where) {
  std::vector<std::string> words;
  for (auto it = options.begin(); it != options.end(); ++it) {
    const std::string& k = it.key();
    if (k.empty() || k[0] == '-') throw malformed(where, "option '" + k + "' must be given without dashes");
    if (kReserved.count(k)) throw malformed(where, "option '" + k + "' is set by glintbake itself");
    const Json& v = it.value();
    auto scalar = [&](const Json& x) -> std::string {
      if (x.is_string()) return x.get<std::string>();
      if (x.is_number()) return x.dump();
      throw malformed(where, "option '" + k + "' must be a boolean, number, string or array of those");
    };
    if (v.is_null()) continue;  // removes a default
    if (v.is_boolean()) {
      words.push_back(v.get<bool>() ? "--" + k : "--no-" + k);
    } else if (v.is_array()) {
      for (const Json& x : v) {
        words.push_back("--" + k);
        words.push_back(scalar(x));
      }
    } else {
      words.push_back("--" + k);
      words.push_back(scalar(v));
    }
  }
  return words;
}

std::vector<std::string> stringList(const Json& j, const std::string& where, const char* field) {
  std::vector<std::string> out;
  if (!j.contains(field)) return out;
  if (!j[field].is_array()) throw malformed(where, std::string("'") + field + "' must be an array of strings");
  for (const Json& x : j[field]) {
    if (!x.is_string() || x.get<std::string>().empty())
      throw malformed(where, std::string("'") + field + "' must be an array of non-empty strings");
    out.push_back(x.get<std::string>());
  }
  return out;
}

std::string selfDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : exe.parent_path().string();
}

// Runs `program --version` and returns its first line of stdout.
std::string versionOf(const std::string& program) {
  const std::string cmd = shellQuote({program, "--version"}) + " 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw Error(cli::kExitIo, "cannot run " + program + " --version");
  std::array<char, 512> buf{};
  std::string out;
  while (fgets(buf.data(), int(buf.size()), p)) out += buf.data();
  const int status = pclose(p);
  if (status != 0 || out.empty()) throw Error(cli::kExitIo, program + " --version failed");
  return out.substr(0, out.find('\n'));
}

}  // namespace

std::string shellQuote(const std::vector<std::string>& argv) {
  std::string s;
  for (const std::string& a : argv) {
    if (!s.empty()) s += ' ';
    const bool plain = !a.empty() && a.find_first_not_of(
                                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                         "_-+=/.,:@%") == std::string::npos;
    if (plain) {
      s += a;
      continue;
    }
    s += '\'';
    for (char c : a) s += c == '\'' ? std::string("'\\''") : std::string(1, c);
    s += '\'';
  }
  return s;
}

Manifest readManifest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(cli::kExitIo, path + ": cannot open (missing or unreadable)");
  std::stringstream text;
  text << in.rdbuf();
  const std::string body = text.str();
  if (format::jsonNestingDepth(body) > size_t(format::kMaxJsonDepth))
    throw malformed(path, "JSON nested deeper than " + std::to_string(format::kMaxJsonDepth) + " levels");
  const Json doc = Json::parse(body, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) throw malformed(path, "not a JSON object");
  if (doc.value("schema", std::string()) != "glintbake.manifest/1")
    throw malformed(path, "'schema' must be \"glintbake.manifest/1\"");
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    if (it.key() != "schema" && it.key() != "defaults" && it.key() != "assets" && it.key() != "state")
      throw malformed(path, "unknown field '" + it.key() + "'");
  }
  Manifest m;
  m.path = path;
  m.dir = fs::path(path).parent_path().string();
  if (m.dir.empty()) m.dir = ".";
  m.state_path = doc.contains("state") && doc["state"].is_string() ? resolve(m.dir, doc["state"].get<std::string>())
                                                                   : path + ".state.json";
  const Json defaults = doc.value("defaults", Json::object());
  if (!defaults.is_object()) throw malformed(path, "'defaults' must be an object");
  if (!doc.contains("assets") || !doc["assets"].is_array() || doc["assets"].empty())
    throw malformed(path, "'assets' must be a non-empty array");
  std::set<std::string> names, outputs;
  size_t index = 0;
  for (const Json& a : doc["assets"]) {
    const std::string where = path + ": assets[" + std::to_string(index++) + "]";
    if (!a.is_object()) throw malformed(where, "not an object");
    for (auto it = a.begin(); it != a.end(); ++it) {
      static const std::set<std::string> kFields = {"name", "tool", "args", "inputs", "output", "options", "shards"};
      if (!kFields.count(it.key())) throw malformed(where, "unknown field '" + it.key() + "'");
    }
    Asset asset;
    asset.tool = a.value("tool", defaults.value("tool", std::string()));
    if (!kTools.count(asset.tool)) throw malformed(where, "'tool' must be one of ndfgen, tensorpack, mapgen, ltcfit");
    if (!a.contains("output") || !a["output"].is_string() || a["output"].get<std::string>().empty())
      throw malformed(where, "'output' (a file name) is required");
    asset.output = resolve(m.dir, a["output"].get<std::string>());
    asset.name = a.value("name", fs::path(asset.output).stem().string());
    if (!names.insert(asset.name).second) throw malformed(where, "asset name '" + asset.name + "' given twice");
    if (!outputs.insert(asset.output).second) throw malformed(where, "output '" + asset.output + "' given twice");
    asset.args = stringList(a, where, "args");
    for (const std::string& i : stringList(a, where, "inputs")) asset.inputs.push_back(resolve(m.dir, i));
    Json options = defaults.value("options", Json::object());
    if (!options.is_object()) throw malformed(path, "'defaults.options' must be an object");
    if (a.contains("options")) {
      if (!a["options"].is_object()) throw malformed(where, "'options' must be an object");
      options.merge_patch(a["options"]);  // null removes a default
    }
    asset.options = optionWords(options, where);
    const Json shards = a.contains("shards") ? a["shards"] : defaults.value("shards", Json(1));
    if (!shards.is_number_integer() || shards.get<int>() < 1 || shards.get<int>() > 4096)
      throw malformed(where, "'shards' must be an integer in [1, 4096]");
    asset.shards = shards.get<int>();
    if (asset.shards > 1 && !kShardedTools.count(asset.tool))
      throw malformed(where, asset.tool + " does not take --shard");
    m.assets.push_back(asset);
  }
  return m;
}

std::string toolPath(const std::string& tool) {
  const fs::path p = fs::path(selfDir()) / tool;
  if (access(p.c_str(), X_OK) != 0) {
    // Build trees keep each tool in its own folder (build/tools/<tool>/<tool>).
    const fs::path sibling = fs::path(selfDir()).parent_path() / tool / tool;
    if (access(sibling.c_str(), X_OK) == 0) return sibling.string();
    throw Error(cli::kExitIo, tool + ": not found beside glintbake (" + p.filename().string() + ")");
  }
  return p.string();
}

void computeKeys(Manifest& m) {
  std::map<std::string, std::string> versions;
  for (Asset& a : m.assets) {
    if (!versions.count(a.tool)) versions[a.tool] = versionOf(toolPath(a.tool));
    a.input_hashes.clear();
    Json key;
    key["tool"] = a.tool;
    key["version"] = versions[a.tool];
    key["args"] = a.args;
    key["options"] = a.options;
    key["shards"] = a.shards;
    key["output"] = fs::path(a.output).filename().string();
    Json inputs = Json::array();
    for (const std::string& in : a.inputs) {
      std::string hex;
      if (format::hashFile128Hex(in, &hex) != format::ContainerStatus::kOk)
        throw Error(cli::kExitIo, a.name + ": input " + in + ": cannot read (missing or unreadable)");
      a.input_hashes.push_back(hex);
      inputs.push_back({{"name", fs::path(in).filename().string()}, {"hash", hex}});
    }
    key["inputs"] = inputs;
    const std::string text = key.dump();
    a.key = format::hash128Hex(text.data(), text.size());
  }
}

std::string partsDir(const Asset& asset) { return asset.output + ".shards"; }

std::string partPath(const Asset& asset, int shard) {
  return (fs::path(partsDir(asset)) /
          (asset.name + "." + std::to_string(shard) + "of" + std::to_string(asset.shards) + ".part.gbk"))
      .string();
}

std::vector<Step> stepsOf(const Manifest& m, size_t index, int threads) {
  const Asset& a = m.assets[index];
  std::vector<Step> steps;
  auto bake = [&](const std::string& out, int shard) {
    Step s;
    s.asset = index;
    s.shard = shard;
    s.argv.push_back(toolPath(a.tool));
    s.argv.insert(s.argv.end(), a.args.begin(), a.args.end());
    s.argv.insert(s.argv.end(), a.inputs.begin(), a.inputs.end());
    s.argv.insert(s.argv.end(), {"-o", out});
    s.argv.insert(s.argv.end(), a.options.begin(), a.options.end());
    if (shard >= 0) s.argv.insert(s.argv.end(), {"--shard", std::to_string(shard) + "/" + std::to_string(a.shards)});
    s.argv.insert(s.argv.end(), {"-j", std::to_string(threads), "--quiet"});
    steps.push_back(s);
  };
  if (a.shards <= 1) {
    bake(a.output, -1);
    return steps;
  }
  for (int i = 0; i < a.shards; ++i) bake(partPath(a, i), i);
  Step merge;
  merge.asset = index;
  merge.merge = true;
  merge.argv = {toolPath("glintinfo"), "merge"};
  for (int i = 0; i < a.shards; ++i) merge.argv.push_back(partPath(a, i));
  merge.argv.insert(merge.argv.end(), {"-o", a.output, "--quiet"});
  steps.push_back(merge);
  return steps;
}

std::map<std::string, StateEntry> readState(const std::string& path) {
  std::map<std::string, StateEntry> state;
  std::ifstream in(path, std::ios::binary);
  if (!in) return state;
  std::stringstream text;
  text << in.rdbuf();
  if (format::jsonNestingDepth(text.str()) > size_t(format::kMaxJsonDepth)) return state;
  const Json doc = Json::parse(text.str(), nullptr, false);
  // An unreadable state only costs a rebake.
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("assets") || !doc["assets"].is_object()) return state;
  for (auto it = doc["assets"].begin(); it != doc["assets"].end(); ++it) {
    if (!it.value().is_object()) continue;
    state[it.key()] =
        StateEntry{it.value().value("key", std::string()), it.value().value("output_hash", std::string())};
  }
  return state;
}

void writeState(const std::string& path, const std::map<std::string, StateEntry>& state) {
  Json doc;
  doc["schema"] = "glintbake.state/1";
  doc["assets"] = Json::object();
  for (const auto& [name, e] : state) doc["assets"][name] = {{"key", e.key}, {"output_hash", e.output_hash}};
  const std::string text = doc.dump(2) + "\n";
  cli::AtomicOutput out(path);
  out.write(text.data(), text.size());
  out.commit();
}

bool upToDate(const Asset& a, const std::map<std::string, StateEntry>& state) {
  const auto it = state.find(a.name);
  if (it == state.end() || it->second.key != a.key) return false;
  std::string hex;
  if (format::hashFile128Hex(a.output, &hex) != format::ContainerStatus::kOk) return false;
  return hex == it->second.output_hash;
}

}  // namespace glintbake::batch
