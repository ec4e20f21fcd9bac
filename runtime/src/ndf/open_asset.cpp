// Opening any NDF asset kind through the NdfSource interface, chosen by the container's kind; the
// file is opened once and the chosen kind loads from the same reader.
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/tensor_ndf.h>
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

}  // namespace

Status openNdfAsset(const char* path, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return Status::kInvalidArgument;
  out->reset();
  if (path == nullptr) return Status::kInvalidArgument;
  format::Reader reader;
  if (format::Status st = reader.open(path); st != format::Status::kOk) return fromFormatStatus(st);
  return loadKind(reader, out);
}

Status openNdfAssetMemory(const void* data, size_t size, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return Status::kInvalidArgument;
  out->reset();
  if (data == nullptr) return Status::kInvalidArgument;
  format::Reader reader;
  if (format::Status st = reader.openMemory(data, size); st != format::Status::kOk) return fromFormatStatus(st);
  return loadKind(reader, out);
}

}  // namespace glintbake::runtime
