// SPDX-License-Identifier: Apache-2.0
// Writes the frozen containers. Run ONCE per set, when the set is introduced; never to "update"
// existing files (see README.md). Not part of the build:
//   c++ -std=c++17 -I formats/include generate_frozen.cpp -L<build>/formats -lglintbake_format ...
//   ./a.out v1_0        v1_0_minimal.gbk, v1_0_image.gbk
//   ./a.out v1_0_kinds  one container per asset kind (frozen_kinds.h)
//   ./a.out v1_0_glitter  the glitter container (frozen_kinds.h), added with the kind
//   ./a.out v1_0_wang  the wang-tiles container (frozen_kinds.h), added with the kind
//   ./a.out v1_0_tiny_example  the tiny-example container (frozen_kinds.h), added with the kind
//   ./a.out v1_0_partial  the partial container (frozen_kinds.h), added with the kind
//   ./a.out v1_0_tiny_example_v2  a tiny-example of record version 2 (layout, overlap), added with it
//   ./a.out v1_0_tiny_example_half  a tiny-example whose levels are binary16 (flag half), added with it
#include "frozen_content.h"
#include "frozen_kinds.h"

#include <glintbake/format/kinds.h>

#include <cstdio>
#include <cstring>

namespace {

using namespace glintbake::format;

struct Section {
  uint32_t type;
  uint64_t key;
  std::vector<uint8_t> bytes;
  Codec codec;
};

bool writeKind(const char* path, AssetKind kind, const char* name, const char* tool,
               const std::vector<Section>& sections) {
  Writer writer;
  if (writer.open(path, kind, 9) != ContainerStatus::kOk) return false;
  if (writer.addMetadata(frozen::kindMetadata(name, tool)) != ContainerStatus::kOk) return false;
  for (const Section& s : sections) {
    if (writer.addSection(s.type, s.key, s.bytes.data(), s.bytes.size(), s.codec) != ContainerStatus::kOk) return false;
  }
  return writer.finish() == ContainerStatus::kOk;
}

int writeKinds() {
  using frozen::ltcSection;
  const bool ok = writeKind("v1_0_ndf_pyramid.gbk", AssetKind::kNdfPyramid, "ndf-pyramid", "ndfgen",
                            {{kSectionNdfLevel, 0, frozen::pyramidLevel(0), Codec::kRaw},
                             {kSectionNdfChunk, 0, frozen::pyramidChunk(0), Codec::kZstd},
                             {kSectionNdfLevel, 1, frozen::pyramidLevel(1), Codec::kRaw},
                             {kSectionNdfChunk, uint64_t(1) << 32, frozen::pyramidChunk(1), Codec::kZstd}}) &&
                  writeKind("v1_0_tensor_ndf.gbk", AssetKind::kTensorNdf, "tensor-ndf", "tensorpack",
                            {{kSectionNdfLevel, 0, frozen::tensorLevel(), Codec::kRaw},
                             {kSectionTensorGroup, 0, frozen::tensorGroup(), Codec::kRaw},
                             {kSectionTensorIndex, 0, frozen::tensorIndex(), Codec::kRaw},
                             {kSectionTensorInfo, 0, frozen::tensorInfo(), Codec::kRaw}}) &&
                  writeKind("v1_0_ltc_table.gbk", AssetKind::kLtcTable, "ltc-table", "ltcfit",
                            {{kSectionLtcTable, 0, ltcSection(0), Codec::kZstd},
                             {kSectionLtcTable, 1, ltcSection(1), Codec::kZstd}}) &&
                  writeKind("v1_0_roughness.gbk", AssetKind::kRoughness, "roughness", "ltcfit",
                            {{kSectionRoughness, 0, frozen::roughnessMip(0), Codec::kRaw},
                             {kSectionRoughness, 1, frozen::roughnessMip(1), Codec::kRaw},
                             {kSectionRoughness, 2, frozen::roughnessMip(2), Codec::kRaw}});
  if (!ok) return 1;
  std::puts("wrote v1_0_ndf_pyramid.gbk, v1_0_tensor_ndf.gbk, v1_0_ltc_table.gbk and v1_0_roughness.gbk");
  return 0;
}

int writeGlitter() {
  if (!writeKind("v1_0_glitter.gbk", AssetKind::kGlitter, "glitter", "ndfgen",
                 {{kSectionGlitterInfo, 0, frozen::glitterRecord(), Codec::kRaw},
                  {kSectionGlitterIntegrals, 0, frozen::glitterIntegrals(), Codec::kZstd}}))
    return 1;
  std::puts("wrote v1_0_glitter.gbk");
  return 0;
}

int writeWang() {
  // The embedded tile asset, written first and read back as bytes.
  if (!writeKind("v1_0_wang_tile.tmp", AssetKind::kNdfPyramid, "ndf-pyramid", "wangtile",
                 {{kSectionNdfLevel, 0, frozen::wangTileLevel(), Codec::kRaw},
                  {kSectionNdfChunk, 0, frozen::wangTileChunk(), Codec::kRaw}}))
    return 1;
  std::vector<uint8_t> tile;
  if (std::FILE* f = std::fopen("v1_0_wang_tile.tmp", "rb")) {
    int c;
    while ((c = std::fgetc(f)) != EOF) tile.push_back(uint8_t(c));
    std::fclose(f);
  }
  std::remove("v1_0_wang_tile.tmp");
  if (tile.empty()) return 1;
  std::vector<Section> sections = {{kSectionWangInfo, 0, frozen::wangRecord(), Codec::kRaw},
                                   {kSectionWangEdges, 0, frozen::wangEdges(), Codec::kZstd},
                                   {kSectionWangTexels, 0, frozen::wangTexels(), Codec::kZstd}};
  for (uint32_t t = 0; t < frozen::kWangTiles; ++t) sections.push_back({kSectionWangTileNdf, t, tile, Codec::kRaw});
  if (!writeKind("v1_0_wang_tiles.gbk", AssetKind::kWangTiles, "wang-tiles", "wangtile", sections)) return 1;
  std::puts("wrote v1_0_wang_tiles.gbk");
  return 0;
}

int writeTinyExample() {
  if (!writeKind("v1_0_tiny_example.gbk", AssetKind::kTinyExample, "tiny-example", "tinyexample",
                 {{kSectionTinyExampleInfo, 0, frozen::tinyRecord(), Codec::kRaw},
                  {kSectionTinyExampleTexels, 0, frozen::tinyTexels(), Codec::kRaw},
                  {kSectionTinyExampleLevel, 0, frozen::tinyLevel(0), Codec::kZstd},
                  {kSectionTinyExampleLevel, 1, frozen::tinyLevel(1), Codec::kZstd}}))
    return 1;
  std::puts("wrote v1_0_tiny_example.gbk");
  return 0;
}

int writeTinyExampleV2() {
  if (!writeKind("v1_0_tiny_example_v2.gbk", AssetKind::kTinyExample, "tiny-example", "tinyexample",
                 {{kSectionTinyExampleInfo, 0, frozen::tinyRecordV2(), Codec::kRaw},
                  {kSectionTinyExampleTexels, 0, frozen::tinyTexels(), Codec::kRaw},
                  {kSectionTinyExampleLevel, 0, frozen::tinyLevel(0), Codec::kZstd},
                  {kSectionTinyExampleLevel, 1, frozen::tinyLevel(1), Codec::kZstd},
                  {kSectionTinyExampleLayout, 0, frozen::tinyLayoutV2(), Codec::kRaw}}))
    return 1;
  std::puts("wrote v1_0_tiny_example_v2.gbk");
  return 0;
}

int writeTinyExampleHalf() {
  if (!writeKind("v1_0_tiny_example_half.gbk", AssetKind::kTinyExample, "tiny-example", "tinyexample",
                 {{kSectionTinyExampleInfo, 0, frozen::tinyRecordHalf(), Codec::kRaw},
                  {kSectionTinyExampleTexels, 0, frozen::tinyTexels(), Codec::kRaw},
                  {kSectionTinyExampleLevelHalf, 0, frozen::tinyLevelHalf(0), Codec::kZstd},
                  {kSectionTinyExampleLevelHalf, 1, frozen::tinyLevelHalf(1), Codec::kZstd}}))
    return 1;
  std::puts("wrote v1_0_tiny_example_half.gbk");
  return 0;
}

int writePartial() {
  if (!writeKind("v1_0_partial.gbk", AssetKind::kPartial, "partial", "ndfgen",
                 {{kSectionShardSection, 1, frozen::shardSection(), Codec::kRaw},
                  {kSectionShardMetadata, 0, frozen::shardMetadata(), Codec::kZstd}}))
    return 1;
  std::puts("wrote v1_0_partial.gbk");
  return 0;
}

int writeV1_0() {
  {
    Writer writer;
    if (writer.open("v1_0_minimal.gbk", AssetKind::kTest) != ContainerStatus::kOk) return 1;
    if (writer.addMetadata(frozen::minimalMetadata()) != ContainerStatus::kOk) return 1;
    if (writer.finish() != ContainerStatus::kOk) return 1;
  }
  {
    Writer writer;
    if (writer.open("v1_0_image.gbk", AssetKind::kTest, 9) != ContainerStatus::kOk) return 1;
    if (writer.addMetadata(frozen::imageMetadata()) != ContainerStatus::kOk) return 1;
    const auto image = frozen::imageSection();
    if (writer.addSection(kSectionImage, frozen::kImageKey, image.data(), image.size(), Codec::kZstd) !=
        ContainerStatus::kOk)
      return 1;
    const auto raw = frozen::privateSection();
    if (writer.addSection(kSectionFirstPrivate, frozen::kPrivateKey, raw.data(), raw.size(), Codec::kRaw) !=
        ContainerStatus::kOk)
      return 1;
    if (writer.finish() != ContainerStatus::kOk) return 1;
  }
  std::puts("wrote v1_0_minimal.gbk and v1_0_image.gbk");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "v1_0") == 0) return writeV1_0();
  if (argc == 2 && std::strcmp(argv[1], "v1_0_kinds") == 0) return writeKinds();
  if (argc == 2 && std::strcmp(argv[1], "v1_0_glitter") == 0) return writeGlitter();
  if (argc == 2 && std::strcmp(argv[1], "v1_0_wang") == 0) return writeWang();
  if (argc == 2 && std::strcmp(argv[1], "v1_0_tiny_example") == 0) return writeTinyExample();
  if (argc == 2 && std::strcmp(argv[1], "v1_0_partial") == 0) return writePartial();
  if (argc == 2 && std::strcmp(argv[1], "v1_0_tiny_example_v2") == 0) return writeTinyExampleV2();
  if (argc == 2 && std::strcmp(argv[1], "v1_0_tiny_example_half") == 0) return writeTinyExampleHalf();
  std::fputs(
      "usage: generate_frozen v1_0 | v1_0_kinds | v1_0_glitter | v1_0_wang | v1_0_tiny_example | v1_0_partial | "
      "v1_0_tiny_example_v2 | v1_0_tiny_example_half\n",
      stderr);
  return 2;
}
