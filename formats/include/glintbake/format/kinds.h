// SPDX-License-Identifier: Apache-2.0
// The registry of asset kinds and section types: the one table every name, range, validator rule,
// C API kind code and metadata string derives from (formats/SPEC.md sections 3 and 4 list the same
// rows; tests/unit/format/kinds_test.cpp checks that they agree).
//
// Adding an asset kind: SPEC.md, "Adding an asset kind", lists every file that changes.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/kinds/partial.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::format {

// Section types of the tiny-example kind (SPEC.md 10.8), in its block 112-127.
constexpr uint32_t kSectionTinyExampleInfo = 112;       // the asset record (key = 0)
constexpr uint32_t kSectionTinyExampleTexels = 113;     // the example's (n_x, n_y) texels (key = 0)
constexpr uint32_t kSectionTinyExampleLevel = 114;      // the tile NDF images of one level (key = level)
constexpr uint32_t kSectionTinyExampleLayout = 115;     // a stochastic layout image (key = 0; version 2)
constexpr uint32_t kSectionTinyExampleLevelHalf = 116;  // one level's tile images as binary16 (key = level; version 2)

// One asset kind: its header value, its stable name (metadata `asset_kind`, glintinfo), the range
// of section types it owns (first..last inclusive; first = last = 0 when it owns none) and the
// program that writes it (empty for kinds no tool writes yet).
struct KindInfo {
  AssetKind kind;
  const char* name;
  uint32_t first_type, last_type;
  const char* tool;
};

// One block of section types reserved by this specification: the types first..last belong to
// `owner` (an asset kind's name, or a shared section family such as "flakes"). Reserved blocks
// without defined types are listed so that no two kinds claim the same numbers. In an `open`
// block every type counts as registered (its kind defines further types per type, as the LTC
// tables do); elsewhere only the types of kSectionTypeRegistry do, and validators warn (3011)
// about the others.
struct SectionRange {
  uint32_t first, last;
  const char* owner;
  bool open;
};

// One defined section type.
struct SectionTypeInfo {
  uint32_t type;
  const char* name;
};

// Every row, in value order. A kind with a writing tool must hold at least one section of its
// range (validators warn 6002 otherwise). Values never change and are never reused (SPEC.md section 6).
constexpr KindInfo kKindRegistry[] = {
    {AssetKind::kNdfPyramid, "ndf-pyramid", 16, 31, "ndfgen"},
    {AssetKind::kTensorNdf, "tensor-ndf", 32, 47, "tensorpack"},
    {AssetKind::kLtcTable, "ltc-table", 48, 63, "ltcfit"},
    {AssetKind::kRoughness, "roughness", 64, 79, "ltcfit"},
    {AssetKind::kWangTiles, "wang-tiles", 96, 111, "wangtile"},
    {AssetKind::kTinyExample, "tiny-example", 112, 127, "tinyexample"},
    {AssetKind::kGlitter, "glitter", 128, 143, "ndfgen"},
    {AssetKind::kPartial, "partial", 144, 159, "ndfgen, tensorpack, wangtile --shard"},
    {AssetKind::kTest, "test", 0, 0, ""},
};

// Reserved section-type blocks (SPEC.md section 3), in value order. "flakes" is a section family
// any NDF asset kind may hold (the source map at float32 precision, for exact small footprints).
constexpr SectionRange kSectionRanges[] = {
    {1, 15, "container", false},    {16, 31, "ndf-pyramid", false},    {32, 47, "tensor-ndf", true},
    {48, 63, "ltc-table", true},    {64, 79, "roughness", true},       {80, 95, "flakes", false},
    {96, 111, "wang-tiles", false}, {112, 127, "tiny-example", false}, {128, 143, "glitter", false},
    {144, 159, "partial", false},   {256, 256, "image", false},
};

constexpr SectionTypeInfo kSectionTypeRegistry[] = {
    {kSectionMetadata, "metadata"},
    {kSectionNdfLevel, "ndf-level"},
    {kSectionNdfChunk, "ndf-chunk"},
    {kSectionTensorIndex, "tensor-index"},
    {kSectionTensorInfo, "tensor-info"},
    {kSectionTensorGroup, "tensor-group"},
    {kSectionLtcTable, "ltc-table"},
    {kSectionRoughness, "roughness"},
    {kSectionFlakes, "flakes"},
    {kSectionWangInfo, "wang-info"},
    {kSectionWangEdges, "wang-edges"},
    {kSectionWangTexels, "wang-texels"},
    {kSectionWangTileNdf, "wang-tile-ndf"},
    {kSectionTinyExampleInfo, "tiny-example-info"},
    {kSectionTinyExampleTexels, "tiny-example-texels"},
    {kSectionTinyExampleLevel, "tiny-example-level"},
    {kSectionTinyExampleLayout, "tiny-example-layout"},
    {kSectionTinyExampleLevelHalf, "tiny-example-level-half"},
    {kSectionGlitterInfo, "glitter-info"},
    {kSectionGlitterIntegrals, "glitter-integrals"},
    {kSectionShardMetadata, "shard-metadata"},
    {kSectionShardSection, "shard-section"},
    {kSectionShardUnit, "shard-unit"},
    {kSectionShardLevels, "shard-levels"},
    {kSectionImage, "image"},
};

// True for the types readers and validators know: defined types, types of open blocks and
// private types.
constexpr bool isRegisteredSectionType(uint32_t type) {
  if (type >= kSectionFirstPrivate) return true;
  for (const SectionTypeInfo& t : kSectionTypeRegistry) {
    if (t.type == type) return true;
  }
  for (const SectionRange& r : kSectionRanges) {
    if (r.open && type >= r.first && type <= r.last) return true;
  }
  return false;
}

// The registry row of a kind, or null for kinds not in the table (kUnknown, unregistered values).
constexpr const KindInfo* findKind(AssetKind kind) {
  for (const KindInfo& k : kKindRegistry) {
    if (k.kind == kind) return &k;
  }
  return nullptr;
}

// The reserved block holding a section type, or null (unreserved, or private >= kSectionFirstPrivate).
constexpr const SectionRange* findSectionRange(uint32_t type) {
  for (const SectionRange& r : kSectionRanges) {
    if (type >= r.first && type <= r.last) return &r;
  }
  return nullptr;
}

}  // namespace glintbake::format
