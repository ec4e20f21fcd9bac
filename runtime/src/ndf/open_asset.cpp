// Opening any NDF asset kind through the NdfSource interface, chosen by the container's kind.
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/tensor_ndf.h>
#include "../flakes/handover.h"
#include "../format_status.h"

#include <new>

namespace glintbake::runtime {
namespace {

template <typename Asset, typename OpenFn>
Status openAs(std::unique_ptr<NdfSource>* out, OpenFn&& open) {
  std::unique_ptr<Asset> asset(new (std::nothrow) Asset());
  if (!asset) return Status::kOutOfMemory;
  if (Status st = open(*asset); st != Status::kOk) return st;
  *out = std::move(asset);
  return Status::kOk;
}

// Dispatches on the kind of an opened reader; `open` loads the chosen asset class.
template <typename OpenFn>
Status openKind(const format::Reader& reader, std::unique_ptr<NdfSource>* out, OpenFn&& open) {
  switch (reader.kind()) {
    case format::AssetKind::kNdfPyramid:
      return openAs<NdfPyramid>(out, open);
    case format::AssetKind::kTensorNdf:
      return openAs<TensorNdf>(out, open);
    default:
      return Status::kWrongKind;
  }
}

// An asset with a flakes section answers small footprints from its flakes (formats/SPEC.md 10.5):
// wraps the opened pyramid-shaped asset into the hand-over.
Status attachFlakes(const format::Reader& reader, std::unique_ptr<NdfSource>* out) {
  const int idx = reader.find(format::kSectionFlakes, 0);
  if (idx < 0) return Status::kOk;
  std::unique_ptr<FlakeNdf> flakes;
  format::FlakesRecord rec;
  if (Status s = loadFlakes(reader, idx, (*out)->resolution(), &flakes, &rec); s != Status::kOk) {
    out->reset();
    return s;
  }
  std::unique_ptr<NdfSource> handover(new (std::nothrow)
                                          HandoverNdf(std::move(flakes), std::move(*out), rec.flakes_up_to, rec.pyramid_from));
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
  if (Status s = openKind(reader, out, [&](auto& asset) { return asset.open(path); }); s != Status::kOk) return s;
  return attachFlakes(reader, out);
}

Status openNdfAssetMemory(const void* data, size_t size, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return Status::kInvalidArgument;
  out->reset();
  if (data == nullptr) return Status::kInvalidArgument;
  format::Reader reader;
  if (format::Status st = reader.openMemory(data, size); st != format::Status::kOk) return fromFormatStatus(st);
  if (Status s = openKind(reader, out, [&](auto& asset) { return asset.openMemory(data, size); }); s != Status::kOk)
    return s;
  return attachFlakes(reader, out);
}

}  // namespace glintbake::runtime
