// SPDX-License-Identifier: Apache-2.0
// The reference renderer of glintref render: direct lighting of one object with a glinty
// microfacet BRDF (runtime/brdf.h) whose D comes from one of three sources:
//  - kReference: the exact P-NDF of the normal map (glintbake::reference: the ground truth, slow;
//    the footprint's flake lobes are gathered once per pixel);
//  - kAsset: a baked NDF asset through the runtime (point queries for point and directional
//    lights, the prefiltered range query for SG environments, NDF sampling for area lights and
//    uniform environments);
//  - kSmooth: the analytic GGX/Beckmann D of the material's base roughness (the look without
//    glints).
//
// One camera ray per pixel, through its centre: the pixel filter is the Gaussian footprint carried
// to the surface by ray differentials, so the NDF query itself integrates over the pixel. Point and
// directional lights are evaluated exactly (no noise); polygons and SG environments use `spp`
// light samples and `spp` BRDF samples combined by multiple importance sampling (power heuristic,
// Veach 1997), or for the smooth BRDF the LTC table (RenderOptions::ltc); the uniform environment
// uses `spp` BRDF samples. Direct lighting only, no shadow rays (a single convex-ish object does
// not shadow itself beyond the horizon test).
//
// Determinism: every pixel draws its random numbers from a counter-based generator keyed by
// (seed, pixel index, light, sample), and pixels are independent, so the image is bit-identical for
// any thread count and scheduling.
#pragma once

#include <glintbake/bake/render/scene.h>
#include <glintbake/bake/result.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

namespace glintbake::runtime {
class NdfSource;
class LtcTable;
}  // namespace glintbake::runtime
namespace glintbake::reference {
struct FlakeSet;
}

namespace glintbake::bake::render {

enum class NdfMode { kReference, kAsset, kSmooth };

// "reference", "asset", "smooth".
const char* ndfModeString(NdfMode mode);
bool ndfModeFromString(const std::string& text, NdfMode* mode);

// How kAsset shades SG environment lights.
enum class EnvMethod { kPrefilter, kSample };

struct RenderOptions {
  NdfMode mode = NdfMode::kSmooth;
  EnvMethod env_method = EnvMethod::kPrefilter;  // kAsset only; the other modes always sample
  int spp = 16;                                  // samples per sampled light, [1, 65536]
  uint64_t seed = 1;
  double sg_epsilon = 1e-3;  // support threshold of SG prefiltering, relative to the amplitude
  // When set, polygon lights are shaded with this GGX LTC table (Heitz et al. 2016; ltcfit table)
  // instead of MIS sampling: noise-free, the reference to compare sampling with. Only with kSmooth
  // and GGX shadowing; Fresnel enters as Schlick with f0 per channel (a conductor's f0 is its
  // reflectance at normal incidence). Borrowed; must outlive the call.
  const runtime::LtcTable* ltc = nullptr;
  // Called from worker threads each time a 16 x 16 tile is finished, with the tile's pixel count
  // (the counts add up to width * height).
  std::function<void(uint64_t pixels_done)> progress;
  const std::atomic<bool>* cancel = nullptr;  // optional: set to stop early (kRuntime error)
};

// The NDF inputs of a render: the flakes of the normal map for kReference, an opened asset for
// kAsset (borrowed; must outlive the call). Map size in texels for the uv -> texel mapping.
struct NdfInputs {
  const reference::FlakeSet* flakes = nullptr;
  const runtime::NdfSource* asset = nullptr;
  int map_width = 0;
  int map_height = 0;
};

struct RenderStats {
  uint64_t pixels_hit = 0;
  double mean_sigma_texels = 0.0;  // mean footprint std over hit pixels
  double max_sigma_texels = 0.0;
  double mean_radiance[3] = {0.0, 0.0, 0.0};  // mean RGB over hit pixels
};

struct RenderedImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3, row 0 at the top
  RenderStats stats;
};

// Renders the scene. Runs on the calling thread's TBB arena (callers limit threads with a
// tbb::task_arena or global_control). Errors: kBadArgument (options out of range, the inputs the
// mode needs are missing), kRuntime (an NDF query failed, cancelled). Thread-safe.
Result<RenderedImage> renderScene(const Scene& scene, const NdfInputs& inputs, const RenderOptions& options);

}  // namespace glintbake::bake::render
