// SPDX-License-Identifier: Apache-2.0
// Render time per NDF mode of the report's far view (examples/scenes/plane_far.json at 64 x 64
// pixels) on a procedural flakes map: the reference P-NDF, the uncompressed ndf-pyramid, the
// rank-16 tensor-ndf and the smooth BRDF. The asset's speedup over the reference is the ratio of
// the medians (scripts/make-report.py prints it for the full-size report scenes).
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/render/renderer.h>
#include <glintbake/bake/render/scene.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/container.h>
#include <glintbake/reference/flakes.h>
#include <glintbake/runtime/ndf_source.h>

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

namespace {

using namespace glintbake;

struct Fixture {
  bake::NormalMap map;
  reference::FlakeSet flakes;
  std::unique_ptr<runtime::NdfSource> pyramid, tensor;
  bake::render::Scene scene;

  Fixture() {
    bake::MapParams mp;
    mp.size = 256;
    mp.seed = 12;
    mp.cone_degrees = 12.0;
    mp.cell = 8.0;
    map = bake::generateMap(bake::MapKind::kFlakes, mp);
    flakes = reference::buildFlakes(map, 1);
    const std::string dir = std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp";
    const std::string pyramid_path = dir + "/bench_render_pyramid.gbk";
    const std::string tensor_path = dir + "/bench_render_tensor.gbk";
    bake::ndf::PyramidOptions po;  // the ndfgen / tensorpack defaults
    {
      format::Writer w;
      if (w.open(pyramid_path, format::AssetKind::kNdfPyramid, 3) != format::ContainerStatus::kOk ||
          !bake::ndf::buildNdfPyramid(map, po, w, nullptr).ok() ||
          w.addMetadata("{}") != format::ContainerStatus::kOk || w.finish() != format::ContainerStatus::kOk) {
        std::fprintf(stderr, "bench_render: cannot bake the pyramid\n");
        std::abort();
      }
    }
    {
      format::Writer w;
      bake::tensor::TensorPackOptions to;
      bake::tensor::TensorPackReport report;
      if (w.open(tensor_path, format::AssetKind::kTensorNdf, 9) != format::ContainerStatus::kOk ||
          !bake::tensor::packTensorNdfFromMap(map, po, to, w, &report).ok() ||
          w.addMetadata("{}") != format::ContainerStatus::kOk || w.finish() != format::ContainerStatus::kOk) {
        std::fprintf(stderr, "bench_render: cannot bake the tensor asset\n");
        std::abort();
      }
    }
    if (runtime::openNdfAsset(pyramid_path.c_str(), &pyramid) != runtime::RuntimeStatus::kOk ||
        runtime::openNdfAsset(tensor_path.c_str(), &tensor) != runtime::RuntimeStatus::kOk) {
      std::fprintf(stderr, "bench_render: cannot open the assets\n");
      std::abort();
    }
    std::remove(pyramid_path.c_str());
    std::remove(tensor_path.c_str());
    const std::string text = R"({
      "camera": {"position": [0, 15.588, 9.0], "look_at": [0, 0, 0], "fov_degrees": 40, "width": 64, "height": 64},
      "object": {"type": "plane", "size": 200.0, "uv_scale": 100.0},
      "material": {"alpha": 0.1, "fresnel": {"type": "conductor"}},
      "lights": [{"type": "point", "position": [5.4, 16.2, -7.2], "intensity": [259.2, 259.2, 259.2]},
                 {"type": "directional", "direction": [-0.2, 0.87, -0.45], "irradiance": [0.6, 0.55, 0.5]}]})";
    auto parsed = bake::render::parseScene(text, "");
    if (!parsed) {
      std::fprintf(stderr, "bench_render: %s\n", parsed.error().message.c_str());
      std::abort();
    }
    scene = parsed.value();
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void renderMode(benchmark::State& state, bake::render::NdfMode mode, const runtime::NdfSource* asset) {
  Fixture& f = fixture();
  bake::render::NdfInputs inputs;
  inputs.flakes = &f.flakes;
  inputs.asset = asset;
  inputs.map_width = f.map.width;
  inputs.map_height = f.map.height;
  bake::render::RenderOptions options;
  options.mode = mode;
  for (auto _ : state) {
    auto image = bake::render::renderScene(f.scene, inputs, options);
    if (!image) state.SkipWithError(image.error().message.c_str());
    benchmark::DoNotOptimize(image);
  }
  state.counters["pixels/s"] = benchmark::Counter(64.0 * 64.0, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_RenderFarReference(benchmark::State& state) { renderMode(state, bake::render::NdfMode::kReference, nullptr); }
void BM_RenderFarPyramid(benchmark::State& state) {
  renderMode(state, bake::render::NdfMode::kAsset, fixture().pyramid.get());
}
void BM_RenderFarTensor16(benchmark::State& state) {
  renderMode(state, bake::render::NdfMode::kAsset, fixture().tensor.get());
}
void BM_RenderFarSmooth(benchmark::State& state) { renderMode(state, bake::render::NdfMode::kSmooth, nullptr); }

BENCHMARK(BM_RenderFarReference)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
BENCHMARK(BM_RenderFarPyramid)->Unit(benchmark::kMillisecond)->Repetitions(3);
BENCHMARK(BM_RenderFarTensor16)->Unit(benchmark::kMillisecond)->Repetitions(3);
BENCHMARK(BM_RenderFarSmooth)->Unit(benchmark::kMillisecond)->Repetitions(3);

}  // namespace

BENCHMARK_MAIN();
