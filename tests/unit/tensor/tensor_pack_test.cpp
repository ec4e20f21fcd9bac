// SPDX-License-Identifier: Apache-2.0
// The tensor-ndf packer: error against the uncompressed pyramid per map kind and rank, blank
// dropping, index consistency, float16 factors, error-target mode, identical bytes from a map and
// from an ndf-pyramid container, and for any thread count.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/container.h>
#include <glintbake/format/numbers.h>
#include <glintbake/runtime/cp_block.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/tensor_ndf.h>
#include <glintbake/runtime/tensor_ndf_layout.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>
#include "../temp_dir.h"

namespace glintbake::bake::tensor {
namespace {

using runtime::NdfLevelRecord;
using runtime::TensorGroupHeader;
using runtime::TensorIndexEntry;
using runtime::TensorInfoRecord;

std::string tempPath(const std::string& name) { return glintbake::testing::processTempDir() + "tensor_pack_" + name; }

std::vector<char> readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// Small pyramids: 64^2 maps, R = 64, two levels; region 3 gives full and partial regions.
ndf::PyramidOptions smallPyramid() {
  ndf::PyramidOptions o;
  o.splat.ndf_res = 64;
  o.stride0 = 16;
  o.sigma0 = 8;
  o.levels = 2;
  o.region_size = 3;
  return o;
}

TensorPackOptions packOptions(int rank) {
  TensorPackOptions o;
  o.cp.rank = rank;
  o.block = 16;
  return o;
}

NormalMap testMap(MapKind kind) {
  MapParams p;
  p.size = 64;
  p.seed = 7;
  return generateMap(kind, p);
}

// The uncompressed pyramid, captured through the builder's sink interface: per level, every
// centre's image in grid order.
class CaptureSink final : public ndf::PyramidSink {
 public:
  struct Level {
    NdfLevelRecord record;
    std::vector<float> images;
  };
  std::vector<Level> levels;

  BakeStatus addLevel(const NdfLevelRecord& record) override {
    Level l;
    l.record = record;
    l.images.assign(size_t(record.grid_width) * record.grid_height * record.ndf_res * record.ndf_res, 0.0f);
    levels.push_back(std::move(l));
    return okStatus();
  }
  BakeStatus addChunk(const ndf::PyramidChunk& chunk) override {
    Level& l = levels.back();
    const size_t image = size_t(chunk.ndf_res) * chunk.ndf_res;
    for (int k = 0; k < chunk.width * chunk.height; ++k) {
      const size_t centre = size_t(chunk.y0 + k / chunk.width) * l.record.grid_width + (chunk.x0 + k % chunk.width);
      std::memcpy(l.images.data() + centre * image, chunk.images + k * image, image * sizeof(float));
    }
    return okStatus();
  }
};

CaptureSink capturePyramid(const NormalMap& map, const ndf::PyramidOptions& o) {
  CaptureSink sink;
  EXPECT_TRUE(ndf::buildNdfPyramid(map, o, sink, nullptr).ok());
  return sink;
}

// A tensor-ndf container decoded independently of the packer, straight from SPEC 10.4.
struct Decoded {
  struct Group {
    TensorGroupHeader header;
    std::vector<float> a, b, c, a_prefix, b_prefix;
  };
  TensorInfoRecord info;
  std::vector<NdfLevelRecord> levels;
  std::vector<std::vector<TensorIndexEntry>> index;
  std::vector<Group> groups;

  // Image of centre `centre` of `level`, reconstructed block by block (0 for blank blocks).
  std::vector<float> image(int level, size_t centre) const {
    const int res = int(info.ndf_res), bins = int(info.block), nb = int(info.blocks_per_side);
    std::vector<float> out(size_t(res) * res, 0.0f);
    for (int blk = 0; blk < nb * nb; ++blk) {
      const TensorIndexEntry e = index[size_t(level)][centre * nb * nb + blk];
      if (e.group == runtime::kTensorBlankGroup) continue;
      const Group& g = groups[e.group];
      const int rank = int(g.header.rank);
      for (int j = 0; j < bins; ++j) {
        for (int i = 0; i < bins; ++i) {
          double v = 0.0;
          for (int r = 0; r < rank; ++r) {
            v += double(g.a[size_t(i) * rank + r]) * g.b[size_t(j) * rank + r] * g.c[size_t(e.row) * rank + r];
          }
          out[size_t((blk / nb) * bins + j) * res + (blk % nb) * bins + i] = float(v);
        }
      }
    }
    return out;
  }
};

template <typename T>
T readRecord(const format::Reader& reader, uint32_t type, uint64_t key) {
  T rec{};
  const int i = reader.find(type, key);
  EXPECT_GE(i, 0) << "section " << type << " key " << key;
  if (i < 0) return rec;
  std::vector<uint8_t> bytes;
  EXPECT_EQ(reader.readSection(size_t(i), &bytes), format::ContainerStatus::kOk);
  EXPECT_EQ(bytes.size(), sizeof(T));
  if (bytes.size() == sizeof(T)) std::memcpy(static_cast<void*>(&rec), bytes.data(), sizeof(T));
  return rec;
}

Decoded decode(const std::string& path) {
  Decoded d;
  format::Reader reader;
  EXPECT_EQ(reader.open(path), format::ContainerStatus::kOk);
  EXPECT_EQ(reader.kind(), format::AssetKind::kTensorNdf);
  d.info = readRecord<TensorInfoRecord>(reader, format::kSectionTensorInfo, 0);
  EXPECT_EQ(d.info.magic, TensorInfoRecord{}.magic);
  EXPECT_EQ(d.info.blocks_per_side * d.info.block, d.info.ndf_res);
  for (uint32_t l = 0; l < d.info.level_count; ++l) {
    d.levels.push_back(readRecord<NdfLevelRecord>(reader, format::kSectionNdfLevel, l));
    std::vector<uint8_t> bytes;
    const int i = reader.find(format::kSectionTensorIndex, l);
    EXPECT_GE(i, 0);
    EXPECT_EQ(reader.readSection(size_t(i), &bytes), format::ContainerStatus::kOk);
    const size_t entries = size_t(d.levels.back().grid_width) * d.levels.back().grid_height * d.info.blocks_per_side *
                           d.info.blocks_per_side;
    EXPECT_EQ(bytes.size(), entries * sizeof(TensorIndexEntry));
    d.index.emplace_back(entries);
    std::memcpy(d.index.back().data(), bytes.data(), std::min(bytes.size(), entries * sizeof(TensorIndexEntry)));
  }
  const size_t e = d.info.precision == 1 ? 2 : 4;
  for (uint32_t g = 0; g < d.info.group_count; ++g) {
    std::vector<uint8_t> bytes;
    const int i = reader.find(format::kSectionTensorGroup, g);
    EXPECT_GE(i, 0);
    EXPECT_EQ(reader.readSection(size_t(i), &bytes), format::ContainerStatus::kOk);
    Decoded::Group grp;
    std::memcpy(&grp.header, bytes.data(), sizeof(grp.header));
    const size_t bins = grp.header.bins, rank = grp.header.rank, blocks = grp.header.blocks;
    EXPECT_EQ(bins, d.info.block);
    EXPECT_LE(rank, d.info.max_rank);
    EXPECT_EQ(bytes.size(), sizeof(grp.header) + e * (2 * bins + blocks) * rank + 8 * (bins + 1) * rank);
    size_t at = sizeof(grp.header);
    auto factor = [&](size_t count, size_t width) {
      std::vector<float> v(count);
      for (size_t n = 0; n < count; ++n, at += width) {
        if (width == 2) {
          uint16_t h;
          std::memcpy(&h, bytes.data() + at, 2);
          v[n] = halfToFloat(h);
        } else {
          std::memcpy(&v[n], bytes.data() + at, 4);
        }
      }
      return v;
    };
    grp.a = factor(bins * rank, e);
    grp.b = factor(bins * rank, e);
    grp.c = factor(blocks * rank, e);
    grp.a_prefix = factor((bins + 1) * rank, 4);
    grp.b_prefix = factor((bins + 1) * rank, 4);
    d.groups.push_back(std::move(grp));
  }
  return d;
}

// Relative L2 error of the decoded asset against the captured pyramid, over every bin.
double decodedError(const Decoded& d, const CaptureSink& ref) {
  double err = 0.0, norm = 0.0;
  const size_t image = size_t(d.info.ndf_res) * d.info.ndf_res;
  for (size_t l = 0; l < ref.levels.size(); ++l) {
    const size_t centres = ref.levels[l].images.size() / image;
    for (size_t c = 0; c < centres; ++c) {
      const std::vector<float> rec = d.image(int(l), c);
      for (size_t n = 0; n < image; ++n) {
        const double x = ref.levels[l].images[c * image + n];
        err += (x - rec[n]) * (x - rec[n]);
        norm += x * x;
      }
    }
  }
  return std::sqrt(err / norm);
}

// sum |D - decoded| / sum |D| over the images of level l (dropped blocks decode to 0).
double decodedL1Error(const Decoded& d, const CaptureSink& ref, size_t l) {
  double err = 0.0, mass = 0.0;
  const size_t image = size_t(d.info.ndf_res) * d.info.ndf_res;
  const size_t centres = ref.levels[l].images.size() / image;
  for (size_t c = 0; c < centres; ++c) {
    const std::vector<float> rec = d.image(int(l), c);
    for (size_t n = 0; n < image; ++n) {
      const double x = ref.levels[l].images[c * image + n];
      err += std::abs(x - rec[n]);
      mass += std::abs(x);
    }
  }
  return err / mass;
}

BakeStatus packFromMap(const NormalMap& map, const TensorPackOptions& o, const std::string& path,
                       TensorPackReport* report, const ndf::PyramidOptions& pyr = smallPyramid()) {
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kTensorNdf, 3), format::ContainerStatus::kOk);
  BakeStatus s = packTensorNdfFromMap(map, pyr, o, w, report);
  if (!s) return s;
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return s;
}

BakeStatus packFromPyramid(const std::string& pyramid_path, const TensorPackOptions& o, const std::string& path,
                           TensorPackReport* report) {
  format::Reader reader;
  EXPECT_EQ(reader.open(pyramid_path), format::ContainerStatus::kOk);
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kTensorNdf, 3), format::ContainerStatus::kOk);
  BakeStatus s = packTensorNdfFromPyramid(reader, o, w, report);
  if (!s) return s;
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return s;
}

std::string writePyramid(const NormalMap& map, const std::string& name) {
  const std::string path = tempPath(name + ".pyramid.gbk");
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kNdfPyramid, 3), format::ContainerStatus::kOk);
  EXPECT_TRUE(ndf::buildNdfPyramid(map, smallPyramid(), w, nullptr).ok());
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return path;
}

TEST(Half, KnownValuesAndRoundTrip) {
  EXPECT_EQ(floatToHalf(1.0f), 0x3C00);
  EXPECT_EQ(floatToHalf(-2.0f), 0xC000);
  EXPECT_EQ(floatToHalf(65504.0f), 0x7BFF);
  EXPECT_EQ(floatToHalf(65519.0f), 0x7BFF);
  EXPECT_EQ(floatToHalf(65520.0f), 0x7C00);  // halfway to 2^16 rounds to even: infinity
  EXPECT_EQ(floatToHalf(std::ldexp(1.0f, -24)), 0x0001);
  EXPECT_EQ(floatToHalf(std::ldexp(1.0f, -25)), 0x0000);         // halfway, even is 0
  EXPECT_EQ(floatToHalf(std::ldexp(3.0f, -25)), 0x0002);         // 1.5 ulp rounds to even 2
  EXPECT_EQ(floatToHalf(1.0f + std::ldexp(1.0f, -11)), 0x3C00);  // halfway, even
  EXPECT_EQ(floatToHalf(1.0f + std::ldexp(3.0f, -11)), 0x3C02);  // halfway, odd rounds up
  EXPECT_EQ(floatToHalf(std::ldexp(1023.5f, -24)), 0x0400);      // subnormal rounds into the normals
  for (uint32_t h = 0; h < 0x10000; ++h) {
    if ((h & 0x7C00) == 0x7C00 && (h & 0x3FF) != 0) continue;  // NaN payloads
    EXPECT_EQ(floatToHalf(halfToFloat(uint16_t(h))), h) << std::hex << h;
  }
}

// Rank 8 > 16 > 32 in relative L2 error against the uncompressed pyramid, on every map kind.
TEST(TensorPack, ErrorFallsWithRankOnEveryMapKind) {
  for (MapKind kind : {MapKind::kFlat, MapKind::kBeckmann, MapKind::kBrushed, MapKind::kScratches, MapKind::kFlakes}) {
    const NormalMap map = testMap(kind);
    const CaptureSink ref = capturePyramid(map, smallPyramid());
    const std::string pyramid = writePyramid(map, mapKindString(kind));
    double errors[3];
    const int ranks[3] = {8, 16, 32};
    for (int n = 0; n < 3; ++n) {
      TensorPackReport rep;
      const std::string out = tempPath(std::string(mapKindString(kind)) + "_r" + std::to_string(ranks[n]) + ".gbk");
      ASSERT_TRUE(packFromPyramid(pyramid, packOptions(ranks[n]), out, &rep).ok());
      const Decoded d = decode(out);
      errors[n] = decodedError(d, ref);
      // The packer's own figure is the error of exactly what it stored.
      EXPECT_NEAR(rep.relative_error, errors[n], 1e-4 + 1e-3 * errors[n]) << mapKindString(kind);
      std::printf(
          "[ figures  ] %-9s rank %2d: relative L2 error %.5f, stored %llu of %llu raw bytes (%.2f%%), "
          "%llu groups, %llu blocks kept, %llu dropped\n",
          mapKindString(kind), ranks[n], errors[n], (unsigned long long)rep.stored_bytes,
          (unsigned long long)rep.raw_bytes, 100.0 * double(rep.stored_bytes) / double(rep.raw_bytes),
          (unsigned long long)rep.groups, (unsigned long long)rep.blocks_kept, (unsigned long long)rep.blocks_dropped);
    }
    if (kind == MapKind::kFlat) {
      // Every image is the same lobe: any rank is nearly exact.
      EXPECT_LT(errors[0], 0.02);
      EXPECT_LE(errors[2], errors[0] + 1e-4);
    } else {
      EXPECT_GT(errors[0], errors[1]) << mapKindString(kind);
      EXPECT_GT(errors[1], errors[2]) << mapKindString(kind);
    }
    EXPECT_LT(errors[2], 0.5) << mapKindString(kind);
    std::remove(pyramid.c_str());
  }
}

// Every index entry points at a block of the right group, blank entries are exactly the blocks
// below the threshold, the prefix sums are those of the stored factors, and the decoded images
// reproduce the report's error.
// The level variation |D - mean| / |D| equals the one computed from the captured images, is near 0
// for a flat map (every footprint sees the same lobe) and clearly positive for a glinty one.
TEST(TensorPack, LevelVariationIsTheSpreadOfTheImagesAboutTheirMean) {
  for (MapKind kind : {MapKind::kFlat, MapKind::kFlakes}) {
    const NormalMap map = testMap(kind);
    const CaptureSink ref = capturePyramid(map, smallPyramid());
    TensorPackReport rep;
    ASSERT_TRUE(
        packFromMap(map, packOptions(8), tempPath(std::string("variation_") + mapKindString(kind) + ".gbk"), &rep)
            .ok());
    ASSERT_EQ(rep.levels.size(), ref.levels.size());
    const size_t image = size_t(rep.ndf_res) * size_t(rep.ndf_res);
    for (size_t l = 0; l < ref.levels.size(); ++l) {
      const std::vector<float>& all = ref.levels[l].images;
      const size_t centres = all.size() / image;
      std::vector<double> mean(image, 0.0);
      for (size_t c = 0; c < centres; ++c)
        for (size_t n = 0; n < image; ++n) mean[n] += all[c * image + n] / double(centres);
      double spread = 0.0, norm = 0.0;
      for (size_t c = 0; c < centres; ++c) {
        for (size_t n = 0; n < image; ++n) {
          const double x = all[c * image + n];
          spread += (x - mean[n]) * (x - mean[n]);
          norm += x * x;
        }
      }
      const double expected = std::sqrt(spread / norm);
      EXPECT_NEAR(rep.levels[l].variation, expected, 1e-6 + 1e-4 * expected) << mapKindString(kind) << " level " << l;
      if (kind == MapKind::kFlat) {
        EXPECT_LT(rep.levels[l].variation, 1e-3);
      } else {
        EXPECT_GT(rep.levels[l].variation, 0.05);
      }
    }
  }
}

// Levels within the exact budget decode to the pyramid's images to float rounding, one rank-B
// group per kept block; the others stay compressed.
TEST(TensorPack, ExactLevelsDecodeToThePyramidImages) {
  const NormalMap map = testMap(MapKind::kFlakes);
  const CaptureSink ref = capturePyramid(map, smallPyramid());
  TensorPackOptions o = packOptions(8);
  // smallPyramid(): level 0 has 4 x 4 centres, level 1 2 x 2 (R = 64); only level 1 fits.
  o.exact_level_bytes = 4 * 64 * 64 * 4;
  TensorPackReport rep;
  const std::string out = tempPath("exact.gbk");
  ASSERT_TRUE(packFromMap(map, o, out, &rep).ok());
  ASSERT_EQ(rep.levels.size(), 2u);
  EXPECT_FALSE(rep.levels[0].exact);
  EXPECT_TRUE(rep.levels[1].exact);
  EXPECT_GT(rep.levels[0].relative_error, 1e-3);
  EXPECT_LT(rep.levels[1].relative_error, 1e-5);  // the blank blocks dropped
  EXPECT_EQ(rep.levels[1].groups, rep.levels[1].blocks_kept);
  const Decoded d = decode(out);
  const size_t image = size_t(d.info.ndf_res) * d.info.ndf_res;
  const std::vector<float>& all = ref.levels[1].images;
  double worst = 0.0, peak = 0.0;
  for (size_t c = 0; c < all.size() / image; ++c) {
    const std::vector<float> rec = d.image(1, c);
    for (size_t n = 0; n < image; ++n) {
      worst = std::max(worst, std::fabs(double(rec[n]) - all[c * image + n]));
      peak = std::max(peak, double(all[c * image + n]));
    }
  }
  EXPECT_LE(worst, 1e-5 * peak);
  // Exact levels count as rank B in the histogram; the compressed ones keep --rank.
  EXPECT_EQ(rep.max_rank, 16);
  EXPECT_GT(rep.rank_histogram[16], 0u);
  EXPECT_GT(rep.rank_histogram[8], 0u);
}

// Levels of more than kMaxExactCentres (16 x 16) centres stay compressed whatever the budget. A
// 16 x 16 exact level answers wide footprints from hundreds of exact blocks per block mix (more
// than a mix has group slots for compressed groups): the asset still equals the uncompressed
// pyramid there, in images, point values and mass, and its sampler's pdf integrates to 1.
TEST(TensorPack, ExactLevelsOfUpTo256CentresAnswerLikeThePyramid) {
  MapParams mp;
  mp.size = 256;
  mp.seed = 3;
  const NormalMap map = generateMap(MapKind::kBeckmann, mp);
  ndf::PyramidOptions pyr;
  pyr.splat.ndf_res = 16;
  pyr.stride0 = 8;  // level 0: 32 x 32 centres, level 1: 16 x 16
  pyr.sigma0 = 4;
  pyr.levels = 2;
  TensorPackOptions o = packOptions(4);
  o.block = 8;
  o.exact_level_bytes = uint64_t(1) << 30;
  TensorPackReport rep;
  const std::string packed = tempPath("exact_cap.gbk");
  ASSERT_TRUE(packFromMap(map, o, packed, &rep, pyr).ok());
  ASSERT_EQ(rep.levels.size(), 2u);
  EXPECT_FALSE(rep.levels[0].exact);
  EXPECT_TRUE(rep.levels[1].exact);

  const std::string plain_path = tempPath("exact_cap.pyramid.gbk");
  {
    format::Writer w;
    ASSERT_EQ(w.open(plain_path, format::AssetKind::kNdfPyramid, 1), format::ContainerStatus::kOk);
    ASSERT_TRUE(ndf::buildNdfPyramid(map, pyr, w, nullptr).ok());
    ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
  }
  runtime::TensorNdf t;
  runtime::NdfPyramid plain;
  ASSERT_EQ(t.open(packed.c_str()), runtime::RuntimeStatus::kOk);
  ASSERT_EQ(plain.open(plain_path.c_str()), runtime::RuntimeStatus::kOk);
  const double level1 = t.level(1)->sigma_texels;
  t.answerFromSigma(level1);
  plain.answerFromSigma(level1);
  const int res = t.resolution();
  std::vector<float> img_t(size_t(res) * res), img_p(size_t(res) * res);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> pos(0.0, 256.0), lsig(std::log(level1), std::log(400.0)), sp(-1.0, 1.0);
  for (int q = 0; q < 12; ++q) {
    const runtime::Footprint fp{pos(rng), pos(rng), std::exp(lsig(rng))};
    ASSERT_EQ(t.image(fp, img_t.data(), img_t.size()), runtime::RuntimeStatus::kOk);
    ASSERT_EQ(plain.image(fp, img_p.data(), img_p.size()), runtime::RuntimeStatus::kOk);
    const float peak = *std::max_element(img_p.begin(), img_p.end());
    for (size_t n = 0; n < img_t.size(); ++n) ASSERT_NEAR(img_t[n], img_p[n], 1e-5 * peak) << "sigma " << fp.sigma;
    for (int k = 0; k < 8; ++k) {
      const runtime::SPoint s{sp(rng), sp(rng)};
      double a = -1.0, b = -1.0;
      ASSERT_EQ(t.eval(fp, s, &a), runtime::RuntimeStatus::kOk);
      ASSERT_EQ(plain.eval(fp, s, &b), runtime::RuntimeStatus::kOk);
      ASSERT_NEAR(a, b, 1e-5 * peak);
    }
    double ma = 0.0, mb = 0.0;
    ASSERT_EQ(t.mass(fp, &ma), runtime::RuntimeStatus::kOk);
    ASSERT_EQ(plain.mass(fp, &mb), runtime::RuntimeStatus::kOk);
    EXPECT_NEAR(ma, mb, 1e-5 * mb);
    // The sampler's density over the bins sums to 1 (bin area (2 / R)^2).
    double total = 0.0;
    for (int j = 0; j < res; ++j) {
      for (int i = 0; i < res; ++i) {
        double p = 0.0;
        const runtime::SPoint s{-1.0 + (i + 0.5) * 2.0 / res, 1.0 - (j + 0.5) * 2.0 / res};
        ASSERT_EQ(t.pdf(fp, s, &p), runtime::RuntimeStatus::kOk);
        total += p * (2.0 / res) * (2.0 / res);
      }
    }
    EXPECT_NEAR(total, 1.0, 1e-5) << "sigma " << fp.sigma;
  }
  std::remove(packed.c_str());
  std::remove(plain_path.c_str());
}

TEST(TensorPack, IndexBlankBlocksAndPrefixSumsAreConsistent) {
  const NormalMap map = testMap(MapKind::kScratches);
  const CaptureSink ref = capturePyramid(map, smallPyramid());
  TensorPackOptions o = packOptions(16);
  o.blank_threshold = 2e-3;  // drops the faint blocks too, not just the empty ones
  TensorPackReport rep;
  const std::string out = tempPath("index.gbk");
  ASSERT_TRUE(packFromMap(map, o, out, &rep).ok());
  const Decoded d = decode(out);
  ASSERT_EQ(d.levels.size(), ref.levels.size());
  EXPECT_GT(rep.blocks_dropped, 0u);
  EXPECT_GT(rep.blocks_kept, 0u);

  const int res = int(d.info.ndf_res), bins = int(d.info.block), nb = int(d.info.blocks_per_side);
  std::vector<std::vector<int>> rows_seen(d.groups.size());
  for (auto& g : rows_seen) g.clear();
  std::vector<std::vector<char>> used(d.groups.size());
  for (size_t g = 0; g < d.groups.size(); ++g) used[g].assign(d.groups[g].header.blocks, 0);
  uint64_t kept = 0, dropped = 0;
  for (size_t l = 0; l < d.levels.size(); ++l) {
    const NdfLevelRecord& lr = d.levels[l];
    for (size_t c = 0; c < size_t(lr.grid_width) * lr.grid_height; ++c) {
      const int cx = int(c % lr.grid_width), cy = int(c / lr.grid_width);
      const uint32_t region = uint32_t((cy / int(lr.region_size)) * int(lr.regions_x) + cx / int(lr.region_size));
      for (int blk = 0; blk < nb * nb; ++blk) {
        double mass = 0.0;
        for (int j = 0; j < bins; ++j) {
          for (int i = 0; i < bins; ++i) {
            mass += ref.levels[l].images[c * res * res + size_t((blk / nb) * bins + j) * res + (blk % nb) * bins + i];
          }
        }
        mass *= (2.0 / res) * (2.0 / res);
        const TensorIndexEntry e = d.index[l][c * nb * nb + blk];
        if (e.group == runtime::kTensorBlankGroup) {
          EXPECT_LT(mass, o.blank_threshold);
          ++dropped;
          continue;
        }
        ++kept;
        EXPECT_GE(mass, o.blank_threshold);
        ASSERT_LT(e.group, d.groups.size());
        const TensorGroupHeader& h = d.groups[e.group].header;
        EXPECT_EQ(h.level, l);
        EXPECT_EQ(h.region, region);
        ASSERT_LT(e.row, h.blocks);
        EXPECT_FALSE(used[e.group][e.row]) << "two entries share a group row";
        used[e.group][e.row] = 1;
      }
    }
  }
  EXPECT_EQ(kept, rep.blocks_kept);
  EXPECT_EQ(dropped, rep.blocks_dropped);
  for (size_t g = 0; g < used.size(); ++g) {
    for (char u : used[g]) EXPECT_TRUE(u) << "group " << g << " has a row no entry uses";
  }
  // Prefix sums: exact partial sums of the stored values, rounded once.
  for (const Decoded::Group& g : d.groups) {
    const int rank = int(g.header.rank);
    for (int r = 0; r < rank; ++r) {
      double sa = 0.0, sb = 0.0;
      EXPECT_EQ(g.a_prefix[size_t(r)], 0.0f);
      for (int t = 1; t <= bins; ++t) {
        sa += g.a[size_t(t - 1) * rank + r];
        sb += g.b[size_t(t - 1) * rank + r];
        EXPECT_EQ(g.a_prefix[size_t(t) * rank + r], float(sa));
        EXPECT_EQ(g.b_prefix[size_t(t) * rank + r], float(sb));
      }
    }
  }
  const double err = decodedError(d, ref);
  EXPECT_NEAR(rep.relative_error, err, 1e-4 + 1e-3 * err);
  // Each level's L1 error is that of its decoded images, the dropped blocks' mass included, and
  // lies well above the Frobenius error on these sparse images (CP spreads mass over many bins).
  for (size_t l = 0; l < d.levels.size(); ++l) {
    const double l1 = decodedL1Error(d, ref, l);
    EXPECT_NEAR(rep.levels[l].l1_error, l1, 1e-4 + 1e-3 * l1) << "level " << l;
    EXPECT_GT(rep.levels[l].l1_error, rep.levels[l].relative_error) << "level " << l;
  }
}

TEST(TensorPack, Float16FactorsHalveTheFactorBytesAtAboutTheSameError) {
  const NormalMap map = testMap(MapKind::kBeckmann);
  const CaptureSink ref = capturePyramid(map, smallPyramid());
  TensorPackReport r32, r16;
  TensorPackOptions o = packOptions(16);
  ASSERT_TRUE(packFromMap(map, o, tempPath("f32.gbk"), &r32).ok());
  o.precision = 1;
  ASSERT_TRUE(packFromMap(map, o, tempPath("f16.gbk"), &r16).ok());
  const Decoded d32 = decode(tempPath("f32.gbk")), d16 = decode(tempPath("f16.gbk"));
  EXPECT_EQ(d16.info.precision, 1u);
  const double e32 = decodedError(d32, ref), e16 = decodedError(d16, ref);
  std::printf("[ figures  ] float32 error %.5f (%llu bytes), float16 error %.5f (%llu bytes)\n", e32,
              (unsigned long long)r32.stored_bytes, e16, (unsigned long long)r16.stored_bytes);
  EXPECT_LT(std::abs(e16 - e32), 2e-3);
  EXPECT_NEAR(r16.relative_error, e16, 1e-4 + 1e-3 * e16);
  EXPECT_LT(r16.stored_bytes, r32.stored_bytes);
  // Float16 values are exactly what the decoder saw: re-rounding changes nothing.
  for (const Decoded::Group& g : d16.groups) {
    for (float v : g.c) EXPECT_EQ(halfToFloat(floatToHalf(v)), v);
  }
}

TEST(TensorPack, ErrorTargetPicksTheSmallestSufficientRankPerGroup) {
  const NormalMap map = testMap(MapKind::kFlakes);
  // At rank 32 every group of this pyramid is below 0.11, so every group can meet 0.15.
  TensorPackOptions fixed = packOptions(32), target = packOptions(32);
  target.error_target = 0.15;
  TensorPackReport rf, rt;
  ASSERT_TRUE(packFromMap(map, fixed, tempPath("fixed.gbk"), &rf).ok());
  ASSERT_TRUE(packFromMap(map, target, tempPath("target.gbk"), &rt).ok());
  const Decoded d = decode(tempPath("target.gbk"));
  std::map<int, uint64_t> histogram;
  for (const Decoded::Group& g : d.groups) {
    ++histogram[int(g.header.rank)];
    EXPECT_LE(g.header.rank, 32u);
  }
  EXPECT_EQ(histogram, rt.rank_histogram);
  EXPECT_LT(rf.max_group_error, 0.15);
  EXPECT_LE(rt.max_group_error, 0.15 + 1e-3) << "some group missed the target";
  EXPECT_LT(rt.stored_bytes, rf.stored_bytes);
  EXPECT_GT(histogram.size(), 0u);
  EXPECT_LT(histogram.begin()->first, 32);
  EXPECT_EQ(d.info.max_rank, uint32_t(histogram.rbegin()->first));
}

TEST(TensorPack, SameBytesFromMapFromPyramidAndForAnyThreadCount) {
  const NormalMap map = testMap(MapKind::kBrushed);
  const std::string pyramid = writePyramid(map, "brushed_same");
  TensorPackOptions o = packOptions(8);
  o.threads = 1;
  ASSERT_TRUE(packFromMap(map, o, tempPath("same_map1.gbk"), nullptr).ok());
  o.threads = 2;
  ASSERT_TRUE(packFromMap(map, o, tempPath("same_map2.gbk"), nullptr).ok());
  ASSERT_TRUE(packFromPyramid(pyramid, o, tempPath("same_pyr.gbk"), nullptr).ok());
  const std::vector<char> a = readAll(tempPath("same_map1.gbk"));
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, readAll(tempPath("same_map2.gbk")));
  EXPECT_EQ(a, readAll(tempPath("same_pyr.gbk")));
  std::remove(pyramid.c_str());
}

TEST(TensorPack, NonNegativeFactorsHaveNoNegativeMass) {
  const NormalMap map = testMap(MapKind::kScratches);
  TensorPackOptions o = packOptions(8);
  o.cp.nonneg = true;
  TensorPackReport rep;
  ASSERT_TRUE(packFromMap(map, o, tempPath("nonneg.gbk"), &rep).ok());
  EXPECT_EQ(rep.negative_mass_fraction, 0.0);
  const Decoded d = decode(tempPath("nonneg.gbk"));
  EXPECT_EQ(d.info.flags & runtime::kTensorFlagNonNegative, runtime::kTensorFlagNonNegative);
  for (const Decoded::Group& g : d.groups) {
    for (float v : g.a) EXPECT_GE(v, 0.0f);
    for (float v : g.c) EXPECT_GE(v, 0.0f);
  }
}

// A map whose normals vary along one coordinate only (x with along_x, otherwise y),
// like a real brushed map: n_x within +-0.02, n_y within +-0.5, smooth periodic profiles.
NormalMap oneAxisMap(int size, bool along_x) {
  NormalMap map;
  map.width = map.height = size;
  map.normals.resize(size_t(size) * size * 3);
  auto profile = [size](double t, double k1, double k2, double phase) {
    const double w = kTwoPi / size;
    return (std::sin(k1 * w * t + phase) + 0.5 * std::sin(k2 * w * t + 2.0 * phase)) / 1.5;
  };
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double t = along_x ? x : y;
      const double nx = 0.02 * profile(t, 3, 7, 0.4), ny = 0.5 * profile(t, 2, 5, 1.3);
      float* n = map.at(x, y);
      n[0] = float(nx);
      n[1] = float(ny);
      n[2] = float(std::sqrt(1.0 - nx * nx - ny * ny));
    }
  }
  return map;
}

TEST(TensorPack, OneAxisMapsPackWithTheDefaults) {
  // The NDF images are lines at s_x ~ 0 on a block boundary: rank-deficient groups, whose default
  // non-negative decomposition used to end in NaN factors (kRuntime, "not finite at the storage
  // precision"). The default pyramid and block, as tensorpack --rank 16 uses them.
  for (bool along_x : {true, false}) {
    for (int precision : {0, 1}) {
      const NormalMap map = oneAxisMap(64, along_x);
      TensorPackOptions o;
      o.cp.nonneg = true;
      o.precision = precision;
      const std::string name = std::string("one_axis_") + (along_x ? "x" : "y") + std::to_string(precision) + ".gbk";
      TensorPackReport rep;
      const ndf::PyramidOptions pyramid;
      const BakeStatus s = packFromMap(map, o, tempPath(name), &rep, pyramid);
      ASSERT_TRUE(s.ok()) << name << ": " << s.error().message;
      EXPECT_TRUE(std::isfinite(rep.relative_error)) << name;
      EXPECT_LT(rep.relative_error, 0.5) << name;
      EXPECT_LT(rep.max_group_error, 0.5) << name;
      EXPECT_EQ(rep.negative_mass_fraction, 0.0) << name;
      const Decoded d = decode(tempPath(name));
      for (const Decoded::Group& g : d.groups) {
        for (const auto* m : {&g.a, &g.b, &g.c}) {
          for (float v : *m) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << name;
        }
      }
      EXPECT_NEAR(decodedError(d, capturePyramid(map, pyramid)), rep.relative_error, 1e-4) << name;
      std::remove(tempPath(name).c_str());
    }
  }
}

TEST(TensorPack, RejectsBadOptionsAndAllBlankPyramids) {
  const NormalMap map = testMap(MapKind::kBeckmann);
  TensorPackOptions o = packOptions(8);
  o.block = 24;  // does not divide 64
  format::Writer w;
  ASSERT_EQ(w.open(tempPath("bad.gbk"), format::AssetKind::kTensorNdf), format::ContainerStatus::kOk);
  BakeStatus s = packTensorNdfFromMap(map, smallPyramid(), o, w, nullptr);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kBadArgument);
  o = packOptions(0);
  EXPECT_EQ(validateTensorPackOptions(o).error().code, ErrorCode::kBadArgument);
  o = packOptions(65);
  EXPECT_FALSE(validateTensorPackOptions(o).ok());
  o = packOptions(8);
  o.error_target = 1.5;
  EXPECT_FALSE(validateTensorPackOptions(o).ok());

  // No block of a normalised image carries more mass than the whole image.
  o = packOptions(8);
  o.blank_threshold = 1.0;
  format::Writer w2;
  ASSERT_EQ(w2.open(tempPath("blank.gbk"), format::AssetKind::kTensorNdf), format::ContainerStatus::kOk);
  s = packTensorNdfFromMap(map, smallPyramid(), o, w2, nullptr);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kInvalidInput);
}

TEST(TensorPack, CancellationStopsWithARuntimeError) {
  const NormalMap map = testMap(MapKind::kBeckmann);
  const std::atomic<bool> cancel{true};
  format::Writer w;
  ASSERT_EQ(w.open(tempPath("cancel.gbk"), format::AssetKind::kTensorNdf), format::ContainerStatus::kOk);
  BakeStatus s = packTensorNdfFromMap(map, smallPyramid(), packOptions(8), w, nullptr, {}, &cancel);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kRuntime);
}

}  // namespace
}  // namespace glintbake::bake::tensor
