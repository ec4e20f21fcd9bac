// SPDX-License-Identifier: Apache-2.0
// Opening any NDF asset kind through the NdfSource interface, chosen by the container's kind; the
// file is opened once and the chosen kind loads from the same reader.
#include <glintbake/format/container.h>
#include <glintbake/runtime/glitter_ndf.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/tensor_ndf.h>
#include <glintbake/runtime/wang_ndf.h>
#include <glintbake/runtime/tiny_example_ndf.h>
#include "../flakes/handover.h"
#include "../format_status.h"

#include <new>

namespace glintbake::runtime {
namespace {

template <typename Asset>
RuntimeStatus loadAs(const format::Reader& reader, std::unique_ptr<NdfSource>* out) {
  std::unique_ptr<Asset> asset(new (std::nothrow) Asset());
  if (!asset) return RuntimeStatus::kOutOfMemory;
  if (RuntimeStatus st = asset->load(reader); st != RuntimeStatus::kOk) return st;
  *out = std::move(asset);
  return RuntimeStatus::kOk;
}

// The NDF asset classes, by the kind of an opened reader.
RuntimeStatus loadKind(const format::Reader& reader, std::unique_ptr<NdfSource>* out) {
  switch (reader.kind()) {
    case format::AssetKind::kNdfPyramid:
      return loadAs<NdfPyramid>(reader, out);
    case format::AssetKind::kTensorNdf:
      return loadAs<TensorNdf>(reader, out);
    case format::AssetKind::kGlitter:
      return loadAs<GlitterNdf>(reader, out);
    case format::AssetKind::kWangTiles:
      return loadAs<WangNdf>(reader, out);
    case format::AssetKind::kTinyExample:
      return loadAs<TinyExampleNdf>(reader, out);
    case format::AssetKind::kPartial:
      return RuntimeStatus::kPartialBake;
    default:
      return RuntimeStatus::kWrongKind;
  }
}

// An asset with a flakes section answers small footprints from its flakes (formats/SPEC.md 10.5):
// wraps the opened pyramid-shaped asset into the hand-over.
RuntimeStatus attachFlakes(const format::Reader& reader, std::unique_ptr<NdfSource>* out) {
  const int idx = reader.find(format::kSectionFlakes, 0);
  if (idx < 0) return RuntimeStatus::kOk;
  FlakePaths paths;
  RuntimeStatus s = loadFlakes(reader, idx, (*out)->resolution(), &paths);
  // The flakes must be those of the pyramid's map.
  const MapSize size = (*out)->mapSize();
  const format::FlakesRecord& rec = paths.record;
  if (s == RuntimeStatus::kOk && (int64_t(rec.map_width) != size.width || int64_t(rec.map_height) != size.height ||
                                  rec.wrap != uint32_t((*out)->wrap())))
    s = RuntimeStatus::kInvalidAsset;
  if (s != RuntimeStatus::kOk) {
    out->reset();
    return s;
  }
  std::unique_ptr<NdfSource> handover(new (std::nothrow) HandoverNdf(std::move(paths), std::move(*out)));
  if (!handover) {
    out->reset();
    return RuntimeStatus::kOutOfMemory;
  }
  *out = std::move(handover);
  return RuntimeStatus::kOk;
}

}  // namespace

RuntimeStatus openNdfAsset(const char* path, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return RuntimeStatus::kInvalidArgument;
  out->reset();
  if (path == nullptr) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (format::ContainerStatus st = reader.open(path); st != format::ContainerStatus::kOk) return fromFormatStatus(st);
  if (RuntimeStatus s = loadKind(reader, out); s != RuntimeStatus::kOk) return s;
  return attachFlakes(reader, out);
}

RuntimeStatus openNdfAssetMemory(const void* data, size_t size, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return RuntimeStatus::kInvalidArgument;
  out->reset();
  if (data == nullptr) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  if (format::ContainerStatus st = reader.openMemory(data, size); st != format::ContainerStatus::kOk)
    return fromFormatStatus(st);
  if (RuntimeStatus s = loadKind(reader, out); s != RuntimeStatus::kOk) return s;
  return attachFlakes(reader, out);
}

}  // namespace glintbake::runtime
