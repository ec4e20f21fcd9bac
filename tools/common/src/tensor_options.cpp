// SPDX-License-Identifier: Apache-2.0
// The CP compression options shared by tensorpack and wangtile (see tensor_options.h).
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/tensor_options.h>

#include <cmath>
#include <optional>

namespace glintbake::cli {

namespace tensor = bake::tensor;

void addTensorPackOptions(CLI::App& app, TensorCliOptions& o, const std::string& seed_name) {
  // Non-negative factors by default. Measured on 256^2 mapgen maps at the default pyramid (R = 128,
  // B = 32): at equal rank their relative error is 1-4% higher than plain ALS (beckmann rank 16:
  // 0.364 vs 0.356), but their files are about half as large (zstd packs the sparse HALS factors
  // well), so at equal file size they are more accurate (beckmann: nonneg rank 32, 0.309 in 204 kB,
  // vs plain rank 16, 0.356 in 247 kB; likewise on brushed, scratches and flakes); and they have no
  // negative density, where plain factors put 1-5% of the absolute density below zero (queries
  // clamp it, so pdf and value / mass disagree there).
  o.pack.cp.nonneg = true;
  tensor::TensorPackOptions& opt = o.pack;
  app.add_option("--rank", opt.cp.rank, "CP rank per group (1..64); the largest rank with --error-target")
      ->capture_default_str();
  app.add_option("--block", opt.block, "Bins per angular block side B (divides --ndf-res)")->capture_default_str();
  app.add_option("--method", o.method_text, "CP method: compressed, als or als-plain")->capture_default_str();
  app.add_flag("--nonneg,!--no-nonneg", opt.cp.nonneg,
               "Non-negative factors (HALS; default on): no negative density anywhere");
  app.add_option("--tol", opt.cp.tol, "Stop when the fit changes by less than this (>= 0)")->capture_default_str();
  app.add_option("--max-iters", opt.cp.max_iters, "Most ALS sweeps per group (>= 1)")->capture_default_str();
  app.add_option("--error-target", o.error_target,
                 "Per group, the smallest rank <= --rank whose relative error is <= this (0..1); a warning when "
                 "the achieved error misses it");
  app.add_option("--blank-threshold", opt.blank_threshold, "Drop blocks whose mass is below this (0..1)")
      ->capture_default_str();
  app.add_option("--precision", o.precision_text, "Factor storage: float32 or float16")->capture_default_str();
  app.add_option("--exact-levels", o.exact_mib,
                 "Store the levels above the finest (and a repeating map's finest level of at most 4 centres) whose "
                 "NDF images take at "
                 "most this many MiB (and 16 x 16 centres) (float32) exactly instead of compressed (0..1024; 0: "
                 "compress every level)")
      ->capture_default_str();
  app.add_option(seed_name, opt.cp.seed,
                 "Seed of the randomised steps of the CP methods (any integer; equal seeds give identical files)")
      ->default_str("fixed")
      ->type_name("INT");
  app.add_option("--zstd-level", o.zstd_level, "zstd compression level of the sections (1..19)")->capture_default_str();
}

void resolveTensorPackOptions(const CLI::App& app, TensorCliOptions& o) {
  const std::optional<tensor::CpMethod> method = tensor::parseCpMethod(o.method_text);
  if (!method) throw Error(kExitBadArguments, "--method must be compressed, als or als-plain");
  o.pack.cp.method = *method;
  if (o.precision_text != "float32" && o.precision_text != "float16") {
    throw Error(kExitBadArguments, "--precision must be float32 or float16");
  }
  o.pack.precision = o.precision_text == "float16" ? 1 : 0;
  o.pack.error_target = o.error_target;
  if (app.count("--error-target") && !(o.error_target >= 0.0 && o.error_target <= 1.0)) {
    throw Error(kExitBadArguments, "--error-target must be in [0, 1]");
  }
  if (o.zstd_level < 1 || o.zstd_level > 19) throw Error(kExitBadArguments, "--zstd-level must be in [1, 19]");
  if (!(o.exact_mib >= 0.0 && o.exact_mib <= 1024.0))
    throw Error(kExitBadArguments, "--exact-levels must be in [0, 1024] MiB");
  o.pack.exact_level_bytes = uint64_t(o.exact_mib * 1048576.0);
  o.pack.exact_min_level = 1;  // level 0's footprints are the lobes' (from single flakes)
  if (bake::BakeStatus s = tensor::validateTensorPackOptions(o.pack); !s)
    throw Error(int(s.error().code), s.error().message);
}

Json tensorPackOptionsJson(const TensorCliOptions& o) {
  const tensor::TensorPackOptions& opt = o.pack;
  Json params;
  params["rank"] = opt.cp.rank;
  params["block"] = opt.block;
  params["method"] = tensor::cpMethodName(opt.cp.method);
  params["nonneg"] = opt.cp.nonneg;
  params["tol"] = opt.cp.tol;
  params["max_iters"] = opt.cp.max_iters;
  params["error_target"] = o.error_target < 0.0 ? Json(nullptr) : Json(o.error_target);
  params["blank_threshold"] = opt.blank_threshold;
  params["precision"] = o.precision_text;
  params["exact_levels_mib"] = o.exact_mib;
  params["seed"] = opt.cp.seed;
  params["zstd_level"] = o.zstd_level;
  return params;
}

}  // namespace glintbake::cli
