// SPDX-License-Identifier: Apache-2.0
// tensorpack: the CP methods on a realistic group (the non-blank 32 x 32 blocks of one 16 x 16
// region of level 0 of a mapgen map's pyramid, R = 128), time and relative error side by side;
// and the whole packer (pyramid generation + CP + writing) on a small map.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/cp_decomposition.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>

#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

namespace bake = glintbake::bake;
namespace ndf = glintbake::bake::ndf;
namespace tensor = glintbake::bake::tensor;

constexpr int kBins = 32;

bake::NormalMap benchMap(bake::MapKind kind) {
  bake::MapParams p;
  p.size = 256;
  p.seed = 42;
  return bake::generateMap(kind, p);
}

ndf::PyramidOptions benchPyramid() {
  ndf::PyramidOptions o;  // R = 128, stride 16, sigma0 8, region 16: the tool's defaults
  o.levels = 1;
  return o;
}

// Keeps the first region of level 0 as a group tensor of its non-empty 32 x 32 blocks, exactly as
// the packer cuts it (blocks with mass below the default blank threshold are dropped).
class FirstGroupSink final : public ndf::PyramidSink {
 public:
  tensor::GroupTensor group;

  bake::BakeStatus addLevel(const glintbake::runtime::NdfLevelRecord&) override { return bake::okStatus(); }
  bake::BakeStatus addChunk(const ndf::PyramidChunk& chunk) override {
    if (chunk.region != 0) return bake::okStatus();
    const int res = chunk.ndf_res, nb = res / kBins;
    group.bins = kBins;
    for (int k = 0; k < chunk.width * chunk.height; ++k) {
      const float* image = chunk.images + size_t(k) * res * res;
      for (int b = 0; b < nb * nb; ++b) {
        std::vector<float> block(size_t(kBins) * kBins);
        double mass = 0.0;
        for (int j = 0; j < kBins; ++j) {
          for (int i = 0; i < kBins; ++i) {
            block[size_t(j) * kBins + i] = image[size_t((b / nb) * kBins + j) * res + (b % nb) * kBins + i];
            mass += block[size_t(j) * kBins + i];
          }
        }
        if (mass * (2.0 / res) * (2.0 / res) < tensor::kDefaultBlankThreshold) continue;
        group.values.insert(group.values.end(), block.begin(), block.end());
        ++group.blocks;
      }
    }
    return bake::okStatus();
  }
};

const tensor::GroupTensor& realGroup(bake::MapKind kind) {
  static std::map<bake::MapKind, tensor::GroupTensor> cache;
  auto it = cache.find(kind);
  if (it == cache.end()) {
    FirstGroupSink sink;
    if (!ndf::buildNdfPyramid(benchMap(kind), benchPyramid(), sink, nullptr).ok()) std::abort();
    it = cache.emplace(kind, std::move(sink.group)).first;
  }
  return it->second;
}

void BM_GroupCp(benchmark::State& state, bake::MapKind kind, tensor::CpMethod method, bool nonneg) {
  const tensor::GroupTensor& group = realGroup(kind);
  tensor::CpOptions o;
  o.rank = 16;
  o.method = method;
  o.nonneg = nonneg;
  tensor::CpFactors last;
  for (auto _ : state) {
    bake::Result<tensor::CpFactors> f = tensor::decomposeCp(group, o);
    if (!f) std::abort();
    last = std::move(f).value();
  }
  // The error is measured outside the timed loop, from the full reconstruction.
  state.counters["K"] = group.blocks;
  state.counters["rel_error"] = tensor::cpReconstructionError(group, last);
  state.counters["sweeps"] = last.sweeps;
}

void BM_PackFromMap(benchmark::State& state) {
  bake::MapParams p;
  p.size = 128;
  p.seed = 3;
  const bake::NormalMap map = bake::generateMap(bake::MapKind::kScratches, p);
  ndf::PyramidOptions pyr;  // tool defaults: R = 128, stride 16, automatic levels
  tensor::TensorPackOptions o;
  o.cp.nonneg = true;  // the tool's default
  tensor::TensorPackReport report;
  const std::string path = "bench_tensorpack_out.gbk";
  for (auto _ : state) {
    glintbake::format::Writer w;
    if (w.open(path, glintbake::format::AssetKind::kTensorNdf, 9) != glintbake::format::ContainerStatus::kOk)
      std::abort();
    if (!tensor::packTensorNdfFromMap(map, pyr, o, w, &report).ok()) std::abort();
    w.abort();
  }
  state.counters["ratio_pct"] = 100.0 * double(report.stored_bytes) / double(report.raw_bytes);
  state.counters["rel_error"] = report.relative_error;
  state.counters["groups"] = double(report.groups);
}
BENCHMARK(BM_PackFromMap)->Unit(benchmark::kMillisecond)->Iterations(3);

const int kRegistered = [] {
  const std::pair<const char*, bake::MapKind> kinds[] = {{"beckmann", bake::MapKind::kBeckmann},
                                                         {"flakes", bake::MapKind::kFlakes},
                                                         {"scratches", bake::MapKind::kScratches}};
  for (const auto& [kind_name, kind] : kinds) {
    for (tensor::CpMethod method : {tensor::CpMethod::kCompressed, tensor::CpMethod::kAlsPlain}) {
      for (bool nonneg : {false, true}) {
        const std::string name = std::string("BM_GroupCp/") + kind_name + "/" + tensor::cpMethodName(method) +
                                 (nonneg ? "/nonneg" : "/signed");
        // The fast methods run in tens of milliseconds: ten runs per repetition steady them.
        benchmark::RegisterBenchmark(name.c_str(), BM_GroupCp, kind, method, nonneg)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(method == tensor::CpMethod::kAlsPlain ? 1 : 10)
            ->Repetitions(5)
            ->ReportAggregatesOnly(true);
      }
    }
  }
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();
