// SPDX-License-Identifier: Apache-2.0
// One tile's NDF asset: the footprint pyramid over the tile's square extended by a margin, each
// image splatting only the tile's own flakes (a clamped map has none outside it), compressed as
// tensorpack compresses a map's pyramid or stored as an ndf-pyramid.
#include <glintbake/bake/ndf/flakes.h>
#include <glintbake/bake/ndf/splat.h>
#include <glintbake/bake/wang/wang.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace glintbake::bake::wang {
namespace {

// The tile seen from the extended square: position (x, y) of the square is (x - M, y - M) of the
// tile. The square is clamped: beyond it the runtime's blend holds the edge centres, whose images
// (a margin away from the tile) are next to nothing, instead of wrapping to the far side.
class TileImageSource final : public ndf::FootprintImageSource {
 public:
  TileImageSource(const ndf::FlakeSet& flakes, const ndf::SplatParams& params, int margin)
      : flakes_(flakes), params_(params), margin_(margin) {}
  void mapSize(int* width, int* height) const override {
    *width = flakes_.map_width + 2 * margin_;
    *height = flakes_.map_height + 2 * margin_;
  }
  void image(double x, double y, double sigma, float* out) const override {
    ndf::Splatter splatter(flakes_, params_);
    splatter.image(x - margin_, y - margin_, sigma, out);
  }
  Wrap wrap() const override { return Wrap::kClamp; }

 private:
  const ndf::FlakeSet& flakes_;
  ndf::SplatParams params_;
  int margin_;
};

BakeStatus readAndRemove(const std::string& path, std::vector<uint8_t>* bytes) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  bool ok = f != nullptr && std::fseek(f, 0, SEEK_END) == 0;
  const long size = ok ? std::ftell(f) : -1;
  ok = ok && size >= 0 && std::fseek(f, 0, SEEK_SET) == 0;
  if (ok) {
    bytes->resize(size_t(size));
    ok = std::fread(bytes->data(), 1, bytes->size(), f) == bytes->size();
  }
  if (f) std::fclose(f);
  std::remove(path.c_str());
  if (!ok) return makeError(ErrorCode::kIo, path + ": cannot read the tile's NDF asset back");
  return okStatus();
}

}  // namespace

BakeStatus bakeWangTileNdf(const WangTileSet& set, int t, const WangNdfOptions& o, const std::string& path,
                           const std::string& metadata_json, std::vector<uint8_t>* bytes, WangTileNdfReport* report,
                           const std::atomic<bool>* cancel) {
  if (t < 0 || t >= set.tile_count) return makeError(ErrorCode::kBadArgument, "tile index out of range");
  if (o.margin < 1) return makeError(ErrorCode::kBadArgument, "the tile margin must be >= 1");
  Result<ndf::FlakeSet> flakes = ndf::buildFlakes(set.tile(t), o.pyramid.rate);
  if (!flakes) return flakes.error();
  const TileImageSource source(flakes.value(), o.pyramid.splat, o.margin);
  format::Writer writer;
  const format::AssetKind kind = o.uncompressed ? format::AssetKind::kNdfPyramid : format::AssetKind::kTensorNdf;
  if (format::ContainerStatus st = writer.open(path, kind, o.zstd_level); st != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, path + ": " + writer.errorString(st));
  WangTileNdfReport local;
  WangTileNdfReport& rep = report ? *report : local;
  const BakeStatus s = o.uncompressed
                           ? ndf::buildNdfPyramid(source, o.pyramid, writer, &rep.pyramid, {}, cancel)
                           : tensor::packTensorNdfFromSource(source, o.pyramid, o.pack, writer, &rep.pack, {}, cancel);
  if (!s) return s;
  if (format::ContainerStatus st = writer.addMetadata(metadata_json); st != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, path + ": " + writer.errorString(st));
  if (format::ContainerStatus st = writer.finish(); st != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, path + ": " + writer.errorString(st));
  return readAndRemove(path, bytes);
}

format::WangRecord wangRecord(const WangTileSet& set, const WangNdfOptions& o, uint64_t grid_seed, double flakes_up_to,
                              double pyramid_from, double max_sigma) {
  format::WangRecord rec;
  rec.colors = uint32_t(set.colors);
  rec.tile_count = uint32_t(set.tile_count);
  rec.tile_size = uint32_t(set.tile_size);
  rec.margin = uint32_t(o.margin);
  rec.seed = grid_seed;
  rec.ndf_res = uint32_t(o.pyramid.splat.ndf_res);
  rec.rate = uint32_t(o.pyramid.rate);
  rec.sigma_r = o.pyramid.splat.sigma_r;
  rec.flakes_up_to = flakes_up_to;
  rec.pyramid_from = pyramid_from;
  rec.max_sigma = max_sigma;
  return rec;
}

Result<std::vector<WangSection>> wangCommonSections(const WangTileSet& set, const format::WangRecord& rec) {
  if (const char* why = format::checkWangRecord(rec)) return makeError(ErrorCode::kBadArgument, why);
  if (int(rec.tile_count) != set.tile_count)
    return makeError(ErrorCode::kBadArgument, "the tile count of the record and the set differ");
  std::vector<WangSection> out(3);
  out[0].type = format::kSectionWangInfo;
  out[0].bytes.resize(sizeof rec);
  std::memcpy(out[0].bytes.data(), &rec, sizeof rec);
  std::vector<uint8_t>& edges = out[1].bytes;
  out[1].type = format::kSectionWangEdges;
  edges.resize(format::wangEdgesBytes(rec));
  for (uint32_t code = 0; code < rec.tile_count; ++code) std::memcpy(&edges[size_t(code) * 4], &code, 4);
  for (int i = 0; i < set.tile_count; ++i)
    std::copy_n(set.edges[size_t(i)].data(), 4, &edges[size_t(rec.tile_count) * 4 + size_t(i) * 4]);
  std::vector<float> texels(format::wangTexelsBytes(rec) / sizeof(float));
  for (size_t k = 0; k * 2 < texels.size(); ++k) {
    texels[2 * k] = set.normals[3 * k];
    texels[2 * k + 1] = set.normals[3 * k + 1];
  }
  out[2].type = format::kSectionWangTexels;
  out[2].bytes.resize(texels.size() * sizeof(float));
  std::memcpy(out[2].bytes.data(), texels.data(), out[2].bytes.size());
  return out;
}

BakeStatus writeWangSections(format::Writer& w, const WangTileSet& set, const format::WangRecord& rec,
                             const std::vector<std::vector<uint8_t>>& tiles) {
  Result<std::vector<WangSection>> common = wangCommonSections(set, rec);
  if (!common) return common.error();
  if (tiles.size() != size_t(set.tile_count))
    return makeError(ErrorCode::kBadArgument, "the tile count of the record, the set and the assets differ");
  format::ContainerStatus st = format::ContainerStatus::kOk;
  for (const WangSection& c : common.value()) {
    if (st == format::ContainerStatus::kOk) st = w.addSection(c.type, 0, c.bytes.data(), c.bytes.size());
  }
  for (int i = 0; i < set.tile_count && st == format::ContainerStatus::kOk; ++i)
    st = w.addSection(format::kSectionWangTileNdf, uint64_t(i), tiles[size_t(i)].data(), tiles[size_t(i)].size());
  if (st != format::ContainerStatus::kOk) return makeError(ErrorCode::kIo, w.errorString(st));
  return okStatus();
}

}  // namespace glintbake::bake::wang
