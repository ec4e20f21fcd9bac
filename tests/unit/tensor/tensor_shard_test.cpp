// SPDX-License-Identifier: Apache-2.0
// Sharded tensor packs: the regions recorded by several shards (TensorShardRecorder) and replayed
// in the asset's order through the TensorAssembler give the asset the one-machine pack writes,
// byte for byte, with compressed and exact levels; malformed units are refused.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_assembly.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/bake/tensor/tensor_shard.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/partial.h>

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>
#include "../temp_dir.h"

namespace glintbake::bake::tensor {
namespace {

std::string tempPath(const std::string& name) { return glintbake::testing::processTempDir() + "tensor_shard_" + name; }

std::vector<char> readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

ndf::PyramidOptions pyramidOptions() {
  ndf::PyramidOptions o;
  o.splat.ndf_res = 32;
  o.stride0 = 8;
  o.sigma0 = 4;
  o.levels = 3;
  o.region_size = 3;
  return o;
}

TensorPackOptions packOptions() {
  TensorPackOptions o;
  o.cp.rank = 4;
  o.block = 8;
  o.exact_level_bytes = 1 << 20;  // levels 1 and 2 of a 64^2 map (4 x 4 and 2 x 2 centres)
  o.exact_min_level = 1;
  return o;
}

uint64_t unitOf(int level, int region) { return uint64_t(level) * 1000 + uint64_t(region); }

// The one-machine pack of `map` into a file; returns its bytes.
std::vector<char> packWhole(const NormalMap& map, const std::string& path) {
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kTensorNdf, 5), format::ContainerStatus::kOk);
  TensorPackReport rep;
  EXPECT_TRUE(packTensorNdfFromMap(map, pyramidOptions(), packOptions(), w, &rep));
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return readAll(path);
}

// Shard i of n: the regions (level * 7 + region) % n == i, recorded into a partial.
void packShard(const NormalMap& map, int i, int n, const std::string& path) {
  format::Writer w;
  ASSERT_EQ(w.open(path, format::AssetKind::kPartial, 3), format::ContainerStatus::kOk);
  ndf::PyramidOptions opt = pyramidOptions();
  opt.region_filter = [i, n](int level, int region) { return (level * 7 + region) % n == i; };
  TensorShardRecorder recorder(w, 5, packOptions().block, unitOf);
  TensorPackReport rep;
  ASSERT_TRUE(packTensorNdfFromMap(map, opt, packOptions(), recorder, &rep));
  ASSERT_TRUE(recorder.finish());
  ASSERT_EQ(recorder.levels().size(), 3u);
  ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
}

std::vector<uint8_t> section(const format::Reader& r, uint32_t type, uint64_t key) {
  std::vector<uint8_t> bytes;
  const int idx = r.find(type, key);
  if (idx >= 0) {
    EXPECT_EQ(r.readSection(size_t(idx), &bytes), format::ContainerStatus::kOk);
  }
  return bytes;
}

// Replays the parts into an asset; returns its bytes.
std::vector<char> mergeParts(const std::vector<std::string>& parts, const std::string& path) {
  std::vector<std::unique_ptr<format::Reader>> readers;
  for (const std::string& p : parts) {
    readers.push_back(std::make_unique<format::Reader>());
    EXPECT_EQ(readers.back()->open(p), format::ContainerStatus::kOk);
  }
  const std::vector<uint8_t> level_bytes = section(*readers[0], format::kSectionShardLevels, 0);
  std::vector<format::NdfLevelRecord> levels(level_bytes.size() / sizeof(format::NdfLevelRecord));
  std::memcpy(static_cast<void*>(levels.data()), level_bytes.data(), level_bytes.size());
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kTensorNdf, 5), format::ContainerStatus::kOk);
  TensorPackReport rep;
  TensorAssembler assembler(w, packOptions(), rep);
  for (const format::NdfLevelRecord& rec : levels) {
    EXPECT_TRUE(assembler.level(rec));
    for (uint32_t r = 0; r < rec.regions_x * rec.regions_y; ++r) {
      int held = 0;
      for (const auto& reader : readers) {
        if (reader->find(format::kSectionShardUnit, unitOf(int(rec.level), int(r))) < 0) continue;
        const std::vector<uint8_t> unit = section(*reader, format::kSectionShardUnit, unitOf(int(rec.level), int(r)));
        EXPECT_TRUE(replayTensorRegion(unit.data(), unit.size(), assembler));
        ++held;
      }
      EXPECT_EQ(held, 1) << "level " << rec.level << " region " << r;
    }
    EXPECT_TRUE(assembler.endLevel());
  }
  EXPECT_TRUE(assembler.finish());
  EXPECT_TRUE(rep.levels[1].exact);
  EXPECT_FALSE(rep.levels[0].exact);
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return readAll(path);
}

NormalMap testMap() {
  MapParams p;
  p.size = 64;
  p.seed = 11;
  return generateMap(MapKind::kScratches, p);
}

TEST(TensorShard, ReplayedShardsGiveTheOneMachineBytes) {
  const NormalMap map = testMap();
  const std::vector<char> whole = packWhole(map, tempPath("whole.gbk"));
  ASSERT_FALSE(whole.empty());
  for (int n : {1, 2, 5}) {
    std::vector<std::string> parts;
    for (int i = 0; i < n; ++i) {
      parts.push_back(tempPath("part" + std::to_string(i) + "of" + std::to_string(n) + ".gbk"));
      packShard(map, i, n, parts.back());
    }
    EXPECT_EQ(mergeParts(parts, tempPath("merged.gbk")), whole) << n << " shards";
  }
}

// A consumer that only counts what reaches it.
class Counter final : public TensorRegionConsumer {
 public:
  BakeStatus level(const format::NdfLevelRecord&) override { return okStatus(); }
  BakeStatus region(const RegionSummary&) override { return okStatus(); }
  BakeStatus group(const GroupStats&, const uint8_t*, size_t, const uint8_t*, size_t, format::Codec) override {
    ++groups;
    return okStatus();
  }
  BakeStatus endRegion() override { return okStatus(); }
  BakeStatus endLevel() override { return okStatus(); }
  int groups = 0;
};

TEST(TensorShard, MalformedUnitsAreRefused) {
  const NormalMap map = testMap();
  const std::string part = tempPath("one.gbk");
  packShard(map, 0, 1, part);
  format::Reader reader;
  ASSERT_EQ(reader.open(part), format::ContainerStatus::kOk);
  const std::vector<uint8_t> unit = section(reader, format::kSectionShardUnit, unitOf(0, 0));
  ASSERT_GT(unit.size(), sizeof(format::TensorShardRegionRecord));
  Counter counter;
  ASSERT_TRUE(replayTensorRegion(unit.data(), unit.size(), counter));
  EXPECT_EQ(counter.groups, 1);
  // Truncated, one byte too many, a bad magic, a block count that does not add up.
  for (size_t cut : {size_t(10), unit.size() / 2, unit.size() - 1}) {
    const BakeStatus s = replayTensorRegion(unit.data(), cut, counter);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().code, ErrorCode::kInvalidInput);
  }
  std::vector<uint8_t> longer = unit;
  longer.push_back(0);
  EXPECT_FALSE(replayTensorRegion(longer.data(), longer.size(), counter));
  std::vector<uint8_t> bad = unit;
  bad[0] ^= 1;
  EXPECT_FALSE(replayTensorRegion(bad.data(), bad.size(), counter));
  bad = unit;
  format::TensorShardRegionRecord rec;
  std::memcpy(&rec, bad.data(), sizeof(rec));
  rec.blocks_dropped += 1;
  std::memcpy(bad.data(), &rec, sizeof(rec));
  EXPECT_FALSE(replayTensorRegion(bad.data(), bad.size(), counter));

  // An index naming a group the region does not have: the assembler refuses it.
  bad = unit;
  format::TensorShardRegionLayout layout;
  ASSERT_EQ(format::checkTensorShardRegion(bad.data(), bad.size(), &layout), nullptr);
  format::TensorIndexEntry e;
  for (uint64_t k = 0; k < layout.index_entries; ++k) {
    std::memcpy(&e, bad.data() + layout.index + k * sizeof(e), sizeof(e));
    if (e.group == format::kTensorBlankGroup) continue;
    e.group = 5;
    std::memcpy(bad.data() + layout.index + k * sizeof(e), &e, sizeof(e));
    break;
  }
  const std::string path = tempPath("bad.gbk");
  format::Writer w;
  ASSERT_EQ(w.open(path, format::AssetKind::kTensorNdf, 5), format::ContainerStatus::kOk);
  TensorPackReport rep;
  TensorAssembler assembler(w, packOptions(), rep);
  const std::vector<uint8_t> level_bytes = section(reader, format::kSectionShardLevels, 0);
  format::NdfLevelRecord level0;
  std::memcpy(&level0, level_bytes.data(), sizeof(level0));
  ASSERT_TRUE(assembler.level(level0));
  const BakeStatus s = replayTensorRegion(bad.data(), bad.size(), assembler);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, ErrorCode::kInvalidInput);
  // Regions out of order are refused too.
  const std::vector<uint8_t> second = section(reader, format::kSectionShardUnit, unitOf(0, 1));
  EXPECT_FALSE(replayTensorRegion(second.data(), second.size(), assembler));
  w.abort();
}

}  // namespace
}  // namespace glintbake::bake::tensor
