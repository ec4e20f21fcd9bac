// SPDX-License-Identifier: Apache-2.0
// Query latency of the tensor-ndf runtime (rank 16, R = 128, blocks of 32; also with the small
// levels stored exactly, tensorpack's default) against the uncompressed ndf-pyramid it was packed
// from: point eval, range average, sample and pdf. Queries
// cycle through 1024 precomputed random footprints, points and uniforms so that neither the
// branch predictor nor the caches see one repeated query.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/tensor_ndf.h>

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

namespace bake = glintbake::bake;
namespace rt = glintbake::runtime;
namespace fmt = glintbake::format;

struct Assets {
  rt::NdfPyramid pyramid;
  rt::TensorNdf tensor;            // plain (signed) CP: tensorpack --no-nonneg
  rt::TensorNdf tensor_nn;         // non-negative CP, every level compressed (--exact-levels 0)
  rt::TensorNdf tensor_ex;         // non-negative CP with the 8 x 8 and 4 x 4 levels exact
  rt::TensorNdf tensor_all_exact;  // every level exact, level 0 of 16 x 16 centres too
};

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "bench_tensor_query: cannot %s\n", what);
  std::abort();
}

void pack(const std::string& pyramid_path, bool nonneg, const std::string& path, rt::TensorNdf* out,
          uint64_t exact_level_bytes = 0) {
  fmt::Reader reader;
  if (reader.open(pyramid_path) != fmt::ContainerStatus::kOk) fail("read the pyramid");
  bake::tensor::TensorPackOptions o;
  o.cp.rank = 16;
  o.cp.nonneg = nonneg;
  o.block = 32;
  o.exact_level_bytes = exact_level_bytes;
  fmt::Writer w;
  bake::tensor::TensorPackReport report;
  if (w.open(path, fmt::AssetKind::kTensorNdf, 1) != fmt::ContainerStatus::kOk ||
      !bake::tensor::packTensorNdfFromPyramid(reader, o, w, &report).ok() ||
      w.addMetadata("{}") != fmt::ContainerStatus::kOk || w.finish() != fmt::ContainerStatus::kOk)
    fail("pack the tensor asset");
  if (out->open(path.c_str()) != rt::RuntimeStatus::kOk) fail("open the tensor asset");
  std::remove(path.c_str());
}

// A 256^2 Beckmann map, R = 128, 16 x 16 level-0 centres, 3 levels; packed at rank 16.
const Assets& assets() {
  static const Assets* a = [] {
    auto* x = new Assets();
    bake::MapParams p;
    p.size = 256;
    p.seed = 42;
    const bake::NormalMap map = bake::generateMap(bake::MapKind::kBeckmann, p);
    bake::ndf::PyramidOptions o;
    o.splat.ndf_res = 128;
    o.stride0 = 16;
    o.sigma0 = 8;
    o.levels = 3;
    const std::string path = "bench_tensor_query_pyramid.gbk";
    fmt::Writer w;
    if (w.open(path, fmt::AssetKind::kNdfPyramid, 1) != fmt::ContainerStatus::kOk ||
        !bake::ndf::buildNdfPyramid(map, o, w, nullptr).ok() || w.addMetadata("{}") != fmt::ContainerStatus::kOk ||
        w.finish() != fmt::ContainerStatus::kOk)
      fail("bake the pyramid");
    if (x->pyramid.open(path.c_str()) != rt::RuntimeStatus::kOk) fail("open the pyramid");
    pack(path, false, "bench_tensor_query_cp.gbk", &x->tensor);
    pack(path, true, "bench_tensor_query_nn.gbk", &x->tensor_nn);
    // A 4 MiB budget: the 8 x 8 and 4 x 4 levels exact, level 0 compressed; 16 MiB (tensorpack's
    // default, without its rule that level 0 stays compressed): every level exact, so that wide
    // footprints blend up to a few hundred exact blocks.
    pack(path, true, "bench_tensor_query_ex.gbk", &x->tensor_ex, uint64_t(4) << 20);
    pack(path, true, "bench_tensor_query_allex.gbk", &x->tensor_all_exact, uint64_t(16) << 20);
    std::remove(path.c_str());
    return x;
  }();
  return *a;
}

struct Query {
  rt::Footprint fp;
  rt::SPoint s;
  rt::SRect rect;
  double u1, u2;
};

const std::vector<Query>& queries() {
  static const std::vector<Query> q = [] {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> pos(0.0, 256.0), lsig(0.0, 6.0), u(0.0, 1.0), s(-0.3, 0.3);
    std::vector<Query> v(1024);
    for (Query& x : v) {
      x.fp.x = pos(rng);
      x.fp.y = pos(rng);
      x.fp.sigma = std::exp2(2.0 + lsig(rng));  // 4 .. 256 texels: every level and beyond
      x.s = rt::SPoint{s(rng), s(rng)};
      x.rect.x0 = x.s.x - 0.05;  // about 6 x 6 bins of R = 128
      x.rect.x1 = x.s.x + 0.05;
      x.rect.y0 = x.s.y - 0.05;
      x.rect.y1 = x.s.y + 0.05;
      x.u1 = u(rng);
      x.u2 = u(rng);
    }
    return v;
  }();
  return q;
}

const rt::NdfSource& source(int which) {
  const Assets& a = assets();
  if (which == 0) return a.tensor;
  if (which == 1) return a.tensor_nn;
  if (which == 3) return a.tensor_ex;
  if (which == 4) return a.tensor_all_exact;
  return a.pyramid;
}

void label(benchmark::State& state) {
  static const char* names[] = {"tensor-cp", "tensor-nonneg", "pyramid", "tensor-exact-levels", "tensor-all-exact"};
  state.SetLabel(names[state.range(0)]);
}

void BM_Eval(benchmark::State& state) {
  const rt::NdfSource& src = source(int(state.range(0)));
  const std::vector<Query>& q = queries();
  size_t k = 0;
  double v = 0.0;
  for (auto _ : state) {
    const Query& x = q[k++ & 1023];
    src.eval(x.fp, x.s, &v);
    benchmark::DoNotOptimize(v);
  }
  label(state);
}
BENCHMARK(BM_Eval)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4);

void BM_Range(benchmark::State& state) {
  const rt::NdfSource& src = source(int(state.range(0)));
  const std::vector<Query>& q = queries();
  size_t k = 0;
  double v = 0.0;
  for (auto _ : state) {
    const Query& x = q[k++ & 1023];
    src.average(x.fp, x.rect, &v);
    benchmark::DoNotOptimize(v);
  }
  label(state);
}
BENCHMARK(BM_Range)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4);

void BM_Sample(benchmark::State& state) {
  const rt::NdfSource& src = source(int(state.range(0)));
  const std::vector<Query>& q = queries();
  size_t k = 0;
  rt::NdfSample s;
  for (auto _ : state) {
    const Query& x = q[k++ & 1023];
    src.sample(x.fp, x.u1, x.u2, &s);
    benchmark::DoNotOptimize(s);
  }
  label(state);
}
BENCHMARK(BM_Sample)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4);

void BM_Pdf(benchmark::State& state) {
  const rt::NdfSource& src = source(int(state.range(0)));
  const std::vector<Query>& q = queries();
  size_t k = 0;
  double v = 0.0;
  for (auto _ : state) {
    const Query& x = q[k++ & 1023];
    src.pdf(x.fp, x.s, &v);
    benchmark::DoNotOptimize(v);
  }
  label(state);
}
BENCHMARK(BM_Pdf)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4);

}  // namespace

BENCHMARK_MAIN();
