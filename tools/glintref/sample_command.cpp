// SPDX-License-Identifier: Apache-2.0
// glintref sample: samples of a footprint's P-NDF (lobe by weight, then the lobe's normal
// Gaussian), as CSV (file or stdout) or inside the --json document.
#include "commands.h"

#include <glintbake/reference/sampling.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace glintbake::glintref {
namespace {

constexpr uint64_t kMaxCount = 100000000;  // 1e8

// Writes the samples as CSV ("sx,sy" header, 17 significant digits) to an open stream.
bool writeCsv(std::FILE* out, reference::PndfSampler& sampler, uint64_t count, double mean[2]) {
  if (std::fputs("sx,sy\n", out) < 0) return false;
  double sum[2] = {0.0, 0.0};
  for (uint64_t n = 0; n < count; ++n) {
    const reference::PndfSample s = sampler.next();
    sum[0] += s.sx;
    sum[1] += s.sy;
    if (std::fprintf(out, "%.17g,%.17g\n", s.sx, s.sy) < 0) return false;
  }
  mean[0] = sum[0] / double(count);
  mean[1] = sum[1] / double(count);
  return true;
}

}  // namespace

CLI::App* addSampleCommand(CLI::App& app, SampleOptions& options) {
  CLI::App* cmd = app.add_subcommand("sample", "Draw samples of a footprint's P-NDF (CSV, or JSON with --json)");
  addQueryOptions(*cmd, options.query);
  cmd->add_option("--count", options.count, "Number of samples (1..1e8)")->required();
  cmd->add_option("--seed", options.seed, "Seed of the random sequence (equal seeds give equal samples)");
  cmd->add_option("-o,--output", options.output,
                  "CSV file of the samples (default: stdout, or in the --json document)");
  return cmd;
}

int runSample(cli::Tool& tool, SampleOptions& options) {
  if (options.count < 1 || options.count > kMaxCount) {
    throw cli::Error(cli::kExitBadArguments, "--count must be in 1..100000000, got " + std::to_string(options.count));
  }
  const Query query = loadQuery(tool, options.query);
  reference::PndfSampler sampler(query.flakes, query.footprint, query.sigma_r, options.seed);
  if (!sampler.valid()) {
    throw cli::Error(cli::kExitBadArguments, "the footprint at --at " + options.query.at_text +
                                                 " sees no flakes of the map (wrap=clamp): nothing to sample");
  }
  const bool json = tool.common().json;
  double mean[2] = {0.0, 0.0};
  cli::Json samples = cli::Json::array();

  if (!options.output.empty()) {
    // The CSV is formatted in memory, then written through one checked atomic write.
    char* buffer = nullptr;
    size_t size = 0;
    std::FILE* file = open_memstream(&buffer, &size);
    if (file == nullptr) throw cli::Error(cli::kExitRuntime, "out of memory");
    const bool ok = writeCsv(file, sampler, options.count, mean);
    const bool closed = std::fclose(file) == 0;
    const std::string text = buffer ? std::string(buffer, size) : std::string();
    std::free(buffer);
    if (!ok || !closed) throw cli::Error(cli::kExitRuntime, "cannot format " + options.output);
    cli::writeOutputFile(options.output, text);
    tool.addOutput(options.output);
  } else if (json) {
    double sum[2] = {0.0, 0.0};
    for (uint64_t n = 0; n < options.count; ++n) {
      const reference::PndfSample s = sampler.next();
      sum[0] += s.sx;
      sum[1] += s.sy;
      samples.push_back({s.sx, s.sy});
    }
    mean[0] = sum[0] / double(options.count);
    mean[1] = sum[1] / double(options.count);
  } else {
    if (!writeCsv(stdout, sampler, options.count, mean)) throw cli::Error(cli::kExitIo, "cannot write to stdout");
  }

  if (json) {
    cli::Json doc;
    doc["tool"] = "glintref";
    doc["command"] = "sample";
    doc.update(queryJson(options.query, query, sampler.lobeCount()));
    doc["count"] = options.count;
    doc["seed"] = options.seed;
    doc["total_weight"] = sampler.totalWeight();
    doc["mean"] = {mean[0], mean[1]};
    if (options.output.empty()) {
      doc["samples"] = std::move(samples);
    } else {
      doc["output"] = {{"name", cli::baseName(options.output)}, {"format", "csv"}};
    }
    tool.printJson(doc);
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintref
