// SPDX-License-Identifier: Apache-2.0
// Test fixtures for the tensor-ndf runtime: small assets packed from procedural maps (built once
// per test program and kept in memory), reconstruction of a centre's image straight from the
// factors, and an ndf-pyramid holding those reconstructions (to compare blending with NdfPyramid).
#pragma once

#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/tensor_ndf.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>
#include "../temp_dir.h"

namespace glintbake::runtime::testing {

inline std::string tempPath(const std::string& name) {
  return glintbake::testing::processTempDir() + "runtime_tensor_" + name;
}

inline std::vector<uint8_t> readFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// 64^2 map, R = 32, blocks of 16 (nb = 2), levels of 4x4, 2x2 and 2x2 centres (the top level's
// sigma 24 is below 0.62 times the map: pyramid_builder.h, levelGeometry), regions of 2x2.
inline bake::ndf::PyramidOptions tinyPyramid() {
  bake::ndf::PyramidOptions o;
  o.splat.ndf_res = 32;
  o.stride0 = 16;
  o.sigma0 = 6;
  o.levels = 3;
  o.region_size = 2;
  return o;
}

inline bake::NormalMap tinyMap(bake::MapKind kind = bake::MapKind::kBeckmann, bool clamp = false) {
  bake::MapParams p;
  p.size = 64;
  p.seed = 11;
  bake::NormalMap map = bake::generateMap(kind, p);
  if (clamp) map.wrap = bake::Wrap::kClamp;
  return map;
}

// Packs `map` into a tensor-ndf container file and returns its bytes (empty on failure).
inline std::vector<uint8_t> packAsset(const bake::NormalMap& map, bool nonneg, int rank, const std::string& name,
                                      int precision = 0, const bake::ndf::PyramidOptions& pyramid = tinyPyramid(),
                                      uint64_t exact_level_bytes = 0) {
  bake::tensor::TensorPackOptions o;
  o.cp.rank = rank;
  o.cp.nonneg = nonneg;
  o.block = 16;
  o.precision = precision;
  o.exact_level_bytes = exact_level_bytes;
  const std::string path = tempPath(name + ".gbk");
  format::Writer w;
  if (w.open(path, format::AssetKind::kTensorNdf, 1) != format::ContainerStatus::kOk) return {};
  bake::tensor::TensorPackReport report;
  const bake::BakeStatus s = bake::tensor::packTensorNdfFromMap(map, pyramid, o, w, &report);
  EXPECT_TRUE(s.ok());
  if (!s.ok() || w.addMetadata("{}") != format::ContainerStatus::kOk || w.finish() != format::ContainerStatus::kOk)
    return {};
  std::vector<uint8_t> bytes = readFile(path);
  std::remove(path.c_str());
  return bytes;
}

// The shared assets of a test program: HALS (non-negative) and plain-ALS packs of one map, and a
// HALS pack whose levels of 2 x 2 centres are stored exactly.
struct Assets {
  std::vector<uint8_t> nonneg_bytes, signed_bytes, exact_bytes;
  TensorNdf nonneg, plain, exact;
};

// Bytes of a level of 2 x 2 centres of tinyPyramid() (R = 32, float32): the exact-level budget.
constexpr uint64_t kTinyExactBytes = 4 * 32 * 32 * 4;

inline const Assets& assets() {
  static const Assets* a = [] {
    auto* x = new Assets();
    const bake::NormalMap map = tinyMap();
    x->nonneg_bytes = packAsset(map, true, 16, "nonneg");
    x->signed_bytes = packAsset(map, false, 16, "signed");
    x->exact_bytes = packAsset(map, true, 16, "exact", 0, tinyPyramid(), kTinyExactBytes);
    EXPECT_EQ(x->exact.openMemory(x->exact_bytes.data(), x->exact_bytes.size()), RuntimeStatus::kOk);
    EXPECT_EQ(x->nonneg.openMemory(x->nonneg_bytes.data(), x->nonneg_bytes.size()), RuntimeStatus::kOk);
    EXPECT_EQ(x->plain.openMemory(x->signed_bytes.data(), x->signed_bytes.size()), RuntimeStatus::kOk);
    return x;
  }();
  return *a;
}

// Unclamped model image of centre (i, j) of level l, in double straight from the factors.
inline std::vector<double> modelImage(const TensorNdf& t, int l, int i, int j) {
  const int res = t.resolution(), bins = int(t.info()->block), nb = int(t.info()->blocks_per_side);
  std::vector<double> img(size_t(res) * res, 0.0);
  for (int blk = 0; blk < nb * nb; ++blk) {
    const TensorIndexEntry* e = t.indexEntry(l, i, j, blk);
    if (!e || e->group == kTensorBlankGroup) continue;
    const CpGroupView& g = *t.group(int(e->group));
    const int bx = blk % nb, by = blk / nb;
    for (int jj = 0; jj < bins; ++jj) {
      for (int ii = 0; ii < bins; ++ii) {
        double v = 0.0;
        for (int r = 0; r < g.rank; ++r)
          v += double(g.a[size_t(ii) * g.rank + r]) * g.b[size_t(jj) * g.rank + r] * g.c[size_t(e->row) * g.rank + r];
        img[size_t(by * bins + jj) * res + size_t(bx * bins + ii)] = v;
      }
    }
  }
  return img;
}

// An ndf-pyramid container with the same levels whose images are the tensor asset's clamped
// reconstructions: NdfPyramid on it is the reference for TensorNdf's blending.
inline std::string writeReconstructedPyramid(const TensorNdf& t, const std::string& name) {
  const std::string path = tempPath(name + ".pyramid.gbk");
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kNdfPyramid, 1), format::ContainerStatus::kOk);
  const int res = t.resolution();
  const size_t image = size_t(res) * res;
  for (int l = 0; l < t.levelCount(); ++l) {
    const NdfLevelRecord rec = *t.level(l);
    EXPECT_EQ(w.addSection(format::kSectionNdfLevel, uint64_t(l), &rec, sizeof(rec)), format::ContainerStatus::kOk);
    for (uint32_t ry = 0; ry < rec.regions_y; ++ry) {
      for (uint32_t rx = 0; rx < rec.regions_x; ++rx) {
        const uint32_t x0 = rx * rec.region_size, y0 = ry * rec.region_size;
        const uint32_t cw = std::min(rec.region_size, rec.grid_width - x0);
        const uint32_t ch = std::min(rec.region_size, rec.grid_height - y0);
        format::ImageSectionHeader h;
        h.width = h.height = uint32_t(res);
        h.channels = 1;
        h.layers = cw * ch;
        std::vector<uint8_t> bytes(sizeof(h) + size_t(cw) * ch * image * 4);
        std::memcpy(bytes.data(), &h, sizeof(h));
        float* dst = reinterpret_cast<float*>(bytes.data() + sizeof(h));
        for (uint32_t k = 0; k < cw * ch; ++k) {
          const std::vector<double> img = modelImage(t, l, int(x0 + k % cw), int(y0 + k / cw));
          for (size_t n = 0; n < image; ++n) dst[k * image + n] = float(std::max(0.0, img[n]));
        }
        const uint64_t key = (uint64_t(l) << 32) | (uint64_t(ry) * rec.regions_x + rx);
        EXPECT_EQ(w.addSection(format::kSectionNdfChunk, key, bytes.data(), bytes.size()),
                  format::ContainerStatus::kOk);
      }
    }
  }
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return path;
}

}  // namespace glintbake::runtime::testing
