// Opening any NDF asset kind through the NdfSource interface, chosen by the container's kind; the
// file is opened once and the chosen kind loads from the same reader.
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/tensor_ndf.h>
#include "../flakes/handover.h"
#include "../format_status.h"

#include <new>

namespace glintbake::runtime {
namespace {

template <typename Asset>
Status loadAs(const format::Reader& reader, std::unique_ptr<NdfSource>* out) {
  std::unique_ptr<Asset> asset(new (std::nothrow) Asset());
  if (!asset) return Status::kOutOfMemory;
  if (Status st = asset->load(reader); st != Status::kOk) return st;
  *out = std::move(asset);
  return Status::kOk;
}

// The NDF asset classes, by the kind of an opened reader.
Status loadKind(const format::Reader& reader, std::unique_ptr<NdfSource>* out) {
  switch (reader.kind()) {
    case format::AssetKind::kNdfPyramid:
      return loadAs<NdfPyramid>(reader, out);
    case format::AssetKind::kTensorNdf:
      return loadAs<TensorNdf>(reader, out);
    default:
      return Status::kWrongKind;
  }
}

// An asset with a flakes section answers small footprints from its flakes (formats/SPEC.md 10.5):
// wraps the opened pyramid-shaped asset into the hand-over.
Status attachFlakes(const format::Reader& reader, std::unique_ptr<NdfSource>* out) {
  const int idx = reader.find(format::kSectionFlakes, 0);
  if (idx < 0) return Status::kOk;
  FlakePaths paths;
  Status s = loadFlakes(reader, idx, (*out)->resolution(), &paths);
  // The flakes must be those of the pyramid's map.
  const MapSize size = (*out)->mapSize();
  const format::FlakesRecord& rec = paths.record;
  if (s == Status::kOk && (int64_t(rec.map_width) != size.width || int64_t(rec.map_height) != size.height ||
                           rec.wrap != uint32_t((*out)->wrap())))
    s = Status::kInvalidAsset;
  if (s != Status::kOk) {
    out->reset();
    return s;
  }
  std::unique_ptr<NdfSource> handover(new (std::nothrow) HandoverNdf(std::move(paths), std::move(*out)));
  if (!handover) {
    out->reset();
    return Status::kOutOfMemory;
  }
  *out = std::move(handover);
  return Status::kOk;
}

}  // namespace

Status openNdfAsset(const char* path, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return Status::kInvalidArgument;
  out->reset();
  if (path == nullptr) return Status::kInvalidArgument;
  format::Reader reader;
  if (format::Status st = reader.open(path); st != format::Status::kOk) return fromFormatStatus(st);
  if (Status s = loadKind(reader, out); s != Status::kOk) return s;
  return attachFlakes(reader, out);
}

Status openNdfAssetMemory(const void* data, size_t size, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return Status::kInvalidArgument;
  out->reset();
  if (data == nullptr) return Status::kInvalidArgument;
  format::Reader reader;
  if (format::Status st = reader.openMemory(data, size); st != format::Status::kOk) return fromFormatStatus(st);
  if (Status s = loadKind(reader, out); s != Status::kOk) return s;
  return attachFlakes(reader, out);
}

}  // namespace glintbake::runtime
