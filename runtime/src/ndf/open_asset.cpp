#include "../format_status.h"
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>

#include <new>

namespace glintbake::runtime {
namespace {

template <typename Asset>
Status openAs(const char* path, std::unique_ptr<NdfSource>* out) {
  std::unique_ptr<Asset> asset(new (std::nothrow) Asset());
  if (!asset) return Status::kOutOfMemory;
  if (Status st = asset->open(path); st != Status::kOk) return st;
  *out = std::move(asset);
  return Status::kOk;
}

}  // namespace

Status openNdfAsset(const char* path, std::unique_ptr<NdfSource>* out) {
  if (out == nullptr) return Status::kInvalidArgument;
  out->reset();
  if (path == nullptr) return Status::kInvalidArgument;
  format::Reader reader;
  if (format::Status st = reader.open(path); st != format::Status::kOk) return fromFormatStatus(st);
  switch (reader.kind()) {
    case format::AssetKind::kNdfPyramid: return openAs<NdfPyramid>(path, out);
    default: return Status::kWrongKind;
  }
}

}  // namespace glintbake::runtime
