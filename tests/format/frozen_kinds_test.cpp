// SPDX-License-Identifier: Apache-2.0
// Reads the frozen 1.0 container of every asset kind and pins its SPEC section 10 records: the
// section bytes equal the encodings of frozen_kinds.h (written from the SPEC's field tables), the
// record structs of formats/include/glintbake/format/kinds/ read the same fields, and every
// record passes its check. README.md: the files are never regenerated.
#include <glintbake/format/binary16.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/glitter.h>
#include <glintbake/format/kinds/ndf_pyramid.h>
#include <glintbake/format/kinds/partial.h>
#include <glintbake/format/kinds/tensor_ndf.h>
#include <glintbake/format/kinds/tiny_example.h>
#include <glintbake/format/kinds/wang.h>
#include <glintbake/format/validate.h>

#include "frozen_kinds.h"

#include <gtest/gtest.h>

#include <cstring>

namespace glintbake::format {
namespace {

std::string frozenKindPath(const char* name) { return std::string(GLINTBAKE_TEST_DATA_DIR) + "/" + name; }

// Opens a frozen file with every check on and expects a clean validation.
void openFrozen(const char* name, AssetKind kind, Reader* reader) {
  ReaderOptions options;
  options.verify_file_checksum = true;
  ASSERT_EQ(reader->open(frozenKindPath(name), options), ContainerStatus::kOk);
  EXPECT_EQ(reader->header().version_major, 1);
  EXPECT_EQ(reader->header().version_minor, 0);
  EXPECT_EQ(reader->kind(), kind);
  const ValidationReport report = validateFile(frozenKindPath(name));
  EXPECT_TRUE(report.valid());
  for (const ValidationMessage& m : report.messages) ADD_FAILURE() << m.id << ": " << m.message;
}

std::vector<uint8_t> section(const Reader& reader, uint32_t type, uint64_t key) {
  std::vector<uint8_t> bytes;
  const int index = reader.find(type, key);
  EXPECT_GE(index, 0) << "type " << type << " key " << key;
  if (index >= 0) {
    EXPECT_EQ(reader.readSection(size_t(index), &bytes), ContainerStatus::kOk);
  }
  return bytes;
}

template <typename Record>
Record as(const std::vector<uint8_t>& bytes) {
  Record r;
  EXPECT_EQ(bytes.size(), sizeof(Record));
  if (bytes.size() == sizeof(Record)) std::memcpy(static_cast<void*>(&r), bytes.data(), sizeof(Record));
  return r;
}

TEST(FrozenKindsV1_0, NdfPyramid) {
  Reader reader;
  openFrozen("v1_0_ndf_pyramid.gbk", AssetKind::kNdfPyramid, &reader);
  ASSERT_EQ(reader.sections().size(), 5u);
  NdfLevelRecord below;
  for (uint32_t l = 0; l < 2; ++l) {
    const std::vector<uint8_t> bytes = section(reader, kSectionNdfLevel, l);
    EXPECT_EQ(bytes, frozen::pyramidLevel(l));
    const NdfLevelRecord rec = as<NdfLevelRecord>(bytes);
    EXPECT_EQ(rec.level, l);
    EXPECT_EQ(rec.ndf_res, 4u);
    EXPECT_EQ(rec.grid_width, l == 0 ? 2u : 1u);
    EXPECT_EQ(rec.map_width, 8u);
    EXPECT_EQ(rec.wrap, 0u);
    EXPECT_EQ(rec.stride_x, l == 0 ? 4.0 : 8.0);
    EXPECT_EQ(rec.origin_y, l == 0 ? 2.0 : 4.0);
    EXPECT_EQ(rec.sigma_texels, l == 0 ? 2.0 : 4.0);
    EXPECT_EQ(rec.sigma_r, 0.005);
    EXPECT_TRUE(checkNdfLevelRecord(rec, l, l > 0 ? &below : nullptr));
    below = rec;
    EXPECT_EQ(section(reader, kSectionNdfChunk, ndfChunkKey(l, 0)), frozen::pyramidChunk(l));
  }
}

TEST(FrozenKindsV1_0, TensorNdf) {
  Reader reader;
  openFrozen("v1_0_tensor_ndf.gbk", AssetKind::kTensorNdf, &reader);
  ASSERT_EQ(reader.sections().size(), 5u);
  const std::vector<uint8_t> info_bytes = section(reader, kSectionTensorInfo, 0);
  EXPECT_EQ(info_bytes, frozen::tensorInfo());
  const TensorInfoRecord info = as<TensorInfoRecord>(info_bytes);
  EXPECT_EQ(info.ndf_res, 4u);
  EXPECT_EQ(info.block, 2u);
  EXPECT_EQ(info.blocks_per_side, 2u);
  EXPECT_EQ(info.level_count, 1u);
  EXPECT_EQ(info.group_count, 1u);
  EXPECT_EQ(info.max_rank, 1u);
  EXPECT_EQ(info.precision, 1u);
  EXPECT_EQ(info.flags, kTensorFlagNonNegative);
  EXPECT_EQ(info.blank_threshold, 1e-6);
  EXPECT_TRUE(checkTensorInfoRecord(info));

  const std::vector<uint8_t> level_bytes = section(reader, kSectionNdfLevel, 0);
  EXPECT_EQ(level_bytes, frozen::tensorLevel());
  const NdfLevelRecord level = as<NdfLevelRecord>(level_bytes);
  EXPECT_EQ(level.wrap, 1u);
  EXPECT_TRUE(checkTensorLevelRecord(level, 0, info, nullptr));

  const std::vector<uint8_t> group_bytes = section(reader, kSectionTensorGroup, 0);
  EXPECT_EQ(group_bytes, frozen::tensorGroup());
  ASSERT_EQ(group_bytes.size(), tensorGroupSectionBytes(2, 1, 2, 1));
  TensorGroupHeader group;
  std::memcpy(&group, group_bytes.data(), sizeof(group));
  EXPECT_EQ(group.bins, 2u);
  EXPECT_EQ(group.rank, 1u);
  EXPECT_EQ(group.blocks, 2u);
  EXPECT_EQ(group.precision, 1u);
  EXPECT_TRUE(checkTensorGroupHeader(group, info, &level));
  // The float16 factors decode to A, B, C.
  for (int v = 0; v < 6; ++v) {
    uint16_t bits;
    std::memcpy(&bits, group_bytes.data() + 32 + 2 * v, 2);
    const float expected = v < 2 ? frozen::kTensorA[v] : v < 4 ? frozen::kTensorB[v - 2] : frozen::kTensorC[v - 4];
    EXPECT_EQ(halfToFloat(bits), expected);
    EXPECT_EQ(floatToHalf(expected), bits);
  }

  const std::vector<uint8_t> index_bytes = section(reader, kSectionTensorIndex, 0);
  EXPECT_EQ(index_bytes, frozen::tensorIndex());
  ASSERT_EQ(index_bytes.size(), 4 * sizeof(TensorIndexEntry));
  TensorIndexEntry entries[4];
  std::memcpy(entries, index_bytes.data(), sizeof(entries));
  EXPECT_EQ(entries[1].group, kTensorBlankGroup);
  EXPECT_EQ(entries[3].row, 1u);
  for (const TensorIndexEntry& e : entries) EXPECT_TRUE(checkTensorIndexEntry(e, &group, 1, 0, 0));
}

TEST(FrozenKindsV1_0, LtcTable) {
  Reader reader;
  openFrozen("v1_0_ltc_table.gbk", AssetKind::kLtcTable, &reader);
  ASSERT_EQ(reader.sections().size(), 3u);
  for (uint64_t key = 0; key < 2; ++key) EXPECT_EQ(section(reader, kSectionLtcTable, key), frozen::ltcSection(key));
}

TEST(FrozenKindsV1_0, Roughness) {
  Reader reader;
  openFrozen("v1_0_roughness.gbk", AssetKind::kRoughness, &reader);
  ASSERT_EQ(reader.sections().size(), 4u);
  for (uint32_t l = 0; l < 3; ++l) EXPECT_EQ(section(reader, kSectionRoughness, l), frozen::roughnessMip(l));
}

TEST(FrozenKindsV1_0, Glitter) {
  Reader reader;
  openFrozen("v1_0_glitter.gbk", AssetKind::kGlitter, &reader);
  ASSERT_EQ(reader.sections().size(), 3u);
  const std::vector<uint8_t> rec = section(reader, kSectionGlitterInfo, 0);
  EXPECT_EQ(rec, frozen::glitterRecord());
  EXPECT_EQ(checkGlitterRecord(as<GlitterRecord>(rec)), nullptr);
  const std::vector<uint8_t> table = section(reader, kSectionGlitterIntegrals, 0);
  EXPECT_EQ(table, frozen::glitterIntegrals());
  std::vector<GlitterIntegral> entries(table.size() / sizeof(GlitterIntegral));
  std::memcpy(static_cast<void*>(entries.data()), table.data(), table.size());
  EXPECT_EQ(checkGlitterIntegrals(entries.data(), entries.size()), nullptr);
}

TEST(FrozenKindsV1_0, WangTiles) {
  Reader reader;
  openFrozen("v1_0_wang_tiles.gbk", AssetKind::kWangTiles, &reader);
  ASSERT_EQ(reader.sections().size(), 4u + frozen::kWangTiles);
  const std::vector<uint8_t> rec_bytes = section(reader, kSectionWangInfo, 0);
  EXPECT_EQ(rec_bytes, frozen::wangRecord());
  const WangRecord rec = as<WangRecord>(rec_bytes);
  EXPECT_EQ(checkWangRecord(rec), nullptr);
  EXPECT_EQ(rec.tile_count, 16u);
  EXPECT_EQ(rec.seed, 3u);
  const std::vector<uint8_t> edges = section(reader, kSectionWangEdges, 0);
  EXPECT_EQ(edges, frozen::wangEdges());
  EXPECT_EQ(checkWangEdges(rec, edges.data(), edges.size()), nullptr);
  EXPECT_EQ(section(reader, kSectionWangTexels, 0), frozen::wangTexels());
  for (uint32_t t = 0; t < frozen::kWangTiles; ++t) {
    const std::vector<uint8_t> tile = section(reader, kSectionWangTileNdf, t);
    Reader inner;
    ASSERT_EQ(inner.openMemory(tile.data(), tile.size()), ContainerStatus::kOk);
    EXPECT_EQ(inner.kind(), AssetKind::kNdfPyramid);
    EXPECT_EQ(section(inner, kSectionNdfLevel, 0), frozen::wangTileLevel());
    EXPECT_EQ(section(inner, kSectionNdfChunk, 0), frozen::wangTileChunk());
  }
  // The grid rule of SPEC 10.7, pinned: the hash and the colours of a few cells.
  EXPECT_EQ(wangVertexHash(0, 0, 3), 0x06c45d188009454full);
  EXPECT_EQ(wangVertexHash(-5, 7, 3), 0xb97d11c5a1cd53e4ull);
  uint8_t e[4];
  wangCellEdges(-5, 7, 2, 3, e);
  EXPECT_EQ(wangTileCode(2, e), 10u);
}

TEST(FrozenKindsV1_0, TinyExample) {
  Reader reader;
  openFrozen("v1_0_tiny_example.gbk", AssetKind::kTinyExample, &reader);
  const std::vector<uint8_t> rec = section(reader, kSectionTinyExampleInfo, 0);
  EXPECT_EQ(rec, frozen::tinyRecord());
  const TinyExampleRecord r = as<TinyExampleRecord>(rec);
  EXPECT_EQ(checkTinyExampleRecord(r), nullptr);
  EXPECT_EQ(r.example_size, 4u);
  EXPECT_EQ(r.levels, 2u);
  EXPECT_EQ(r.ndf_res, 4u);
  EXPECT_EQ(r.sigma_r, 0.05);
  EXPECT_EQ(section(reader, kSectionTinyExampleTexels, 0), frozen::tinyTexels());
  EXPECT_EQ(section(reader, kSectionTinyExampleLevel, 0), frozen::tinyLevel(0));
  EXPECT_EQ(section(reader, kSectionTinyExampleLevel, 1), frozen::tinyLevel(1));
  EXPECT_EQ(section(reader, kSectionTinyExampleLevel, 1).size(), tinyLevelSectionSize(r, 1));
}

// Record version 2: a layout image and overlapping examples; the placement rules pinned on it.
// Levels as binary16 (flag half, section 116): the record and the sections' bytes.
TEST(FrozenKindsV1_0, TinyExampleHalf) {
  Reader reader;
  openFrozen("v1_0_tiny_example_half.gbk", AssetKind::kTinyExample, &reader);
  const std::vector<uint8_t> rec = section(reader, kSectionTinyExampleInfo, 0);
  EXPECT_EQ(rec, frozen::tinyRecordHalf());
  const TinyExampleRecord r = as<TinyExampleRecord>(rec);
  EXPECT_EQ(checkTinyExampleRecord(r), nullptr);
  EXPECT_EQ(r.flags, kTinyFlagHalf);
  EXPECT_EQ(section(reader, kSectionTinyExampleLevelHalf, 0), frozen::tinyLevelHalf(0));
  EXPECT_EQ(section(reader, kSectionTinyExampleLevelHalf, 1), frozen::tinyLevelHalf(1));
  EXPECT_EQ(tinyLevelSectionSize(r, 0), 32u + 2u * 16u * 4u);
  EXPECT_LT(reader.find(kSectionTinyExampleLevel, 0), 0);
}

TEST(FrozenKindsV1_0, TinyExampleVersion2) {
  Reader reader;
  openFrozen("v1_0_tiny_example_v2.gbk", AssetKind::kTinyExample, &reader);
  const std::vector<uint8_t> rec = section(reader, kSectionTinyExampleInfo, 0);
  EXPECT_EQ(rec, frozen::tinyRecordV2());
  const TinyExampleRecord r = as<TinyExampleRecord>(rec);
  EXPECT_EQ(checkTinyExampleRecord(r), nullptr);
  EXPECT_EQ(r.version, 2u);
  EXPECT_EQ(r.flags, kTinyFlagLayout | kTinyFlagOverlap);
  const std::vector<uint8_t> layout_bytes = section(reader, kSectionTinyExampleLayout, 0);
  EXPECT_EQ(layout_bytes, frozen::tinyLayoutV2());
  std::vector<float> values(4);
  std::memcpy(values.data(), layout_bytes.data() + 32, 16);
  const TinyLayout layout{2, 1, 2, values.data()};
  EXPECT_EQ(checkTinyLayout(layout), nullptr);
  EXPECT_EQ(tinyOverlapReach(r), 2);
  // Odd columns of cells have presence 0; even ones always hold an example, rotated by 90 degrees,
  // its centre inside its cell.
  for (int64_t j = -3; j <= 3; ++j) {
    for (int64_t i = -4; i <= 4; ++i) {
      const TinyPlacement p = tinyCellPlacement(r, i, j, &layout);
      EXPECT_EQ(p.present, (i & 1) == 0) << i << "," << j;
      if (!p.present) continue;
      EXPECT_NEAR(p.matrix[0], 0.0, 1e-15);
      EXPECT_EQ(p.matrix[1], 1.0);
      EXPECT_EQ(p.matrix[2], -1.0);
      EXPECT_GE(p.centre[0], 2.0 * double(i));
      EXPECT_LT(p.centre[0], 2.0 * double(i + 1));
    }
  }
  // Without its layout the record places nothing (the layout is part of the asset).
  EXPECT_FALSE(tinyCellPlacement(r, 0, 0).present);
}

TEST(FrozenKindsV1_0, Partial) {
  Reader reader;
  openFrozen("v1_0_partial.gbk", AssetKind::kPartial, &reader);
  ASSERT_EQ(reader.sections().size(), 3u);
  const std::vector<uint8_t> held = section(reader, kSectionShardSection, 1);
  EXPECT_EQ(held, frozen::shardSection());
  ShardSectionHeader h;
  ASSERT_GE(held.size(), sizeof(h));
  std::memcpy(&h, held.data(), sizeof(h));
  EXPECT_EQ(checkShardSectionHeader(h, held.size()), nullptr);
  EXPECT_EQ(section(reader, kSectionShardMetadata, 0), frozen::shardMetadata());
}

}  // namespace
}  // namespace glintbake::format
