// SPDX-License-Identifier: Apache-2.0
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/pyramid_options.h>

#include <glintbake/bake/ndf/flakes_section.h>

#include <cctype>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace glintbake::cli {

void addPyramidOptions(CLI::App& app, PyramidCliOptions& p, const std::string& region_help) {
  bake::ndf::PyramidOptions& o = p.options;
  p.flags = {
      app.add_option("--ndf-res", o.splat.ndf_res, "NDF image resolution R (bins per side, 2..4096)")
          ->capture_default_str(),
      app.add_option("--sigma-r", o.splat.sigma_r, "Intrinsic roughness: s-plane std of every flake (0, 1]")
          ->capture_default_str(),
      app.add_option("--stride", o.stride0, "Level-0 spacing of footprint centres, texels (> 0)")
          ->capture_default_str(),
      app.add_option("--sigma0", o.sigma0, "Level-0 footprint std, texels (> 0)")->capture_default_str(),
      app.add_option("--levels", p.levels_text,
                     "Number of levels, or auto (stop on convergence once the grid is at most 16 x 16, or at a 1x1 "
                     "grid)")
          ->capture_default_str(),
      app.add_option("--converge-mse", o.converge_mse,
                     "auto levels: stop when the relative MSE between neighbouring levels is below this")
          ->capture_default_str(),
      app.add_option("--rate", o.rate, "Flakes per texel side (1..16)")->capture_default_str(),
      app.add_option("--region", o.region_size, region_help)->capture_default_str(),
      app.add_option("--footprint-truncation", o.splat.footprint_truncation,
                     "Footprints leave out flakes beyond this many stds, the others reweighed to unit mass "
                     "(1..10; 4: images about 3x closer to the exact ones, for about 25% more bake time)")
          ->capture_default_str(),
      app.add_flag("!--no-flakes", p.flakes,
                   "Leave out the flakes section (the normal map, float32) that answers footprints up to "
                   "4 texels exactly and mid-size ones from clustered lobes"),
      app.add_option("--lobes", p.lobes,
                     "Lobes per tile of the clustered path between the flakes and the pyramid (0..16; 0: the "
                     "flakes hand over to the pyramid at max(4, sigma0))")
          ->capture_default_str(),
  };
  // Not among `flags`: it applies to every input, a container as well as a map.
  app.add_option("--max-memory", p.max_memory_text,
                 "Refuse the bake up front when its estimated peak memory exceeds this many bytes (suffix K, M, "
                 "G or T: powers of 1024)");
}

uint64_t estimateBakeBytes(const PyramidCliOptions& p, const bake::NormalMap& map, int threads, bool tensor) {
  const bake::ndf::PyramidOptions& o = p.options;
  const double texels = double(map.width) * double(map.height);
  const double rate2 = double(o.rate) * double(o.rate);
  const double r2 = double(o.splat.ndf_res) * double(o.splat.ndf_res);
  const double region2 = double(o.region_size) * double(o.region_size);
  double bytes = texels * 3 * 4                                   // the map's normals
                 + texels * rate2 * 24                            // its flakes
                 + 2 * region2 * r2 * 4                           // two chunks
                 + (double(threads) + 16) * r2 * 8;               // scratch, and split footprints
  if (tensor) bytes += (double(threads) + 1) * region2 * r2 * 4;  // group tensors in flight
  return bytes >= 1.8e19 ? UINT64_MAX : uint64_t(bytes);
}

void checkMemoryBudget(const PyramidCliOptions& p, const bake::NormalMap& map, int threads, bool tensor) {
  if (p.max_memory_text.empty()) return;
  uint64_t limit = 0;
  try {
    size_t used = 0;
    const double value = std::stod(p.max_memory_text, &used);
    const std::string suffix = p.max_memory_text.substr(used);
    static const std::string kSuffixes = "KMGT";
    double scale = 1.0;
    if (suffix.size() == 1 &&
        kSuffixes.find(char(std::toupper(static_cast<unsigned char>(suffix[0])))) != std::string::npos) {
      const size_t power = kSuffixes.find(char(std::toupper(static_cast<unsigned char>(suffix[0])))) + 1;
      for (size_t k = 0; k < power; ++k) scale *= 1024.0;
    } else if (!suffix.empty()) {
      throw std::invalid_argument("suffix");
    }
    if (!(value > 0) || value * scale >= 1.8e19) throw std::invalid_argument("range");
    limit = uint64_t(value * scale);
  } catch (const std::exception&) {
    throw Error(kExitBadArguments, "--max-memory must be a positive number of bytes, optionally with K, M, G or T");
  }
  const uint64_t estimate = estimateBakeBytes(p, map, threads, tensor);
  if (estimate > limit) {
    throw Error(kExitRuntime, "the bake needs about " + std::to_string((estimate + (1u << 20) - 1) >> 20) +
                                  " MiB (map " + std::to_string(map.width) + "x" + std::to_string(map.height) +
                                  "), more than --max-memory " + p.max_memory_text);
  }
}

void resolvePyramidOptions(PyramidCliOptions& p) {
  if (p.levels_text == "auto") {
    p.options.levels = 0;
  } else {
    try {
      size_t used = 0;
      p.options.levels = std::stoi(p.levels_text, &used);
      if (used != p.levels_text.size() || p.options.levels < 1) throw std::invalid_argument("levels");
    } catch (const std::exception&) {
      throw Error(kExitBadArguments, "--levels must be auto or a positive integer");
    }
  }
  check(bake::ndf::validatePyramidOptions(p.options));
  if (p.lobes < 0 || p.lobes > bake::ndf::kMaxLobesPerTile)
    throw Error(kExitBadArguments, "--lobes must be in [0, 16]");
}

Json pyramidOptionsJson(const PyramidCliOptions& p) {
  const bake::ndf::PyramidOptions& o = p.options;
  Json j;
  j["ndf_res"] = o.splat.ndf_res;
  j["sigma_r"] = o.splat.sigma_r;
  j["stride"] = o.stride0;
  j["sigma0"] = o.sigma0;
  j["levels"] = p.levels_text == "auto" ? Json("auto") : Json(o.levels);
  j["converge_mse"] = o.converge_mse;
  j["rate"] = o.rate;
  j["region"] = o.region_size;
  j["footprint_truncation"] = o.splat.footprint_truncation;
  j["flakes"] = p.flakes;
  j["lobes"] = p.lobes;
  return j;
}

bake::ndf::FlakesHandover defaultFlakesHandover(const PyramidCliOptions& p, const bake::NormalMap& map) {
  return bake::ndf::fitHandoverToMap(bake::ndf::defaultHandover(p.options.sigma0, p.lobes), map.width, map.height,
                                     map.wrap == bake::Wrap::kRepeat, p.options.rate);
}

uint64_t writeFlakes(format::Writer& writer, const bake::NormalMap& map, const PyramidCliOptions& p,
                     const bake::ndf::FlakesHandover& handover) {
  if (!p.flakes) return 0;
  uint64_t bytes = 0;
  const bake::BakeStatus s =
      bake::ndf::writeFlakesSection(writer, map, p.options.rate, p.options.splat.sigma_r, handover, &bytes);
  if (!s) throw Error(int(s.error().code), s.error().message);
  return bytes;
}

Json flakesJson(const bake::ndf::FlakesHandover& h, uint64_t bytes) {
  Json j = {{"up_to", h.flakes_up_to}, {"pyramid_from", h.pyramid_from}, {"bytes", bytes}};
  j["lobes_per_tile"] = h.lobes_per_tile;
  if (h.lobes_per_tile > 0) j["lobes_up_to"] = h.lobes_up_to;
  return j;
}

void requireBakeableMap(const bake::NormalMap& map, const std::string& path) {
  if (map.width < 2 || map.height < 2) {
    throw Error(kExitInvalidInput, path + ": a normal map needs at least 2x2 texels (got " + std::to_string(map.width) +
                                       "x" + std::to_string(map.height) + ")");
  }
}

bake::ndf::PyramidProgress LevelProgress::callback() {
  return [this](int level, uint64_t done, uint64_t total) {
    if (level != level_) {
      finish();
      bar_ = tool_.progress("level " + std::to_string(level), total);
      level_ = level;
      done_ = 0;
    }
    bar_->advance(done - done_);
    done_ = done;
  };
}

void LevelProgress::finish() {
  if (bar_) bar_->finish();
  bar_.reset();
}

}  // namespace glintbake::cli
