// One tile's NDF asset: the footprint pyramid over the tile's square extended by a margin, each
// image splatting only the tile's own flakes (a clamped map has none outside it), compressed as
// tensorpack compresses a map's pyramid or stored as an ndf-pyramid.
#include <glintbake/bake/ndf/flakes.h>
#include <glintbake/bake/ndf/splat.h>
#include <glintbake/bake/wang/wang.h>

#include <cstdio>
#include <fstream>
#include <iterator>

namespace glintbake::bake::wang {
namespace {

// The tile seen from the extended square: position (x, y) of the square is (x - M, y - M) of the tile.
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

 private:
  const ndf::FlakeSet& flakes_;
  ndf::SplatParams params_;
  int margin_;
};

BakeStatus readAndRemove(const std::string& path, std::vector<uint8_t>* bytes) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return makeError(ErrorCode::kIo, path + ": cannot read the tile's NDF asset back");
  bytes->assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  f.close();
  std::remove(path.c_str());
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
  const BakeStatus s = o.uncompressed ? ndf::buildNdfPyramid(source, o.pyramid, writer, &rep.pyramid, {}, cancel)
                                      : tensor::packTensorNdfFromSource(source, o.pyramid, o.pack, writer, &rep.pack,
                                                                        {}, cancel);
  if (!s) return s;
  if (format::ContainerStatus st = writer.addMetadata(metadata_json); st != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, path + ": " + writer.errorString(st));
  if (format::ContainerStatus st = writer.finish(); st != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, path + ": " + writer.errorString(st));
  return readAndRemove(path, bytes);
}

}  // namespace glintbake::bake::wang
