// SPDX-License-Identifier: Apache-2.0
// An opened NDF asset file: its NdfSource (the queries, ndf_source.h) together with what the
// container says about it (kind, metadata JSON), and open failures explained by the validator.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_source.h>

#include <cstddef>
#include <cstdint>
#include <memory>

namespace glintbake::runtime {

// Why an open failed. message_id is the validator's stable id (formats/SPEC.md "Validation",
// e.g. 1001 the file cannot be read, 2011 newer major version, 4001 a section checksum differs) of
// the first error it finds in the file, and message its one-line text; message_id is 0 when the
// validator finds the container sound and the runtime refused it for another reason (an asset kind
// that is not an NDF, a kind record it does not support), message then says that reason.
struct OpenError {
  static constexpr size_t kMessageCapacity = 256;
  RuntimeStatus status = RuntimeStatus::kOk;
  int32_t message_id = 0;
  char message[kMessageCapacity] = {};  // NUL-terminated, truncated to fit
};

class NdfAsset {
 public:
  NdfAsset();
  ~NdfAsset();
  NdfAsset(const NdfAsset&) = delete;
  NdfAsset& operator=(const NdfAsset&) = delete;

  // Opens any NDF asset kind (ndf-pyramid, tensor-ndf, glitter; with flakes when stored). Statuses
  // as openNdfAsset; error (may be null) is filled on failure and reset on success. Safe on
  // untrusted input. On failure the asset stays closed. Not thread-safe with queries on this object.
  RuntimeStatus open(const char* path, OpenError* error = nullptr);
  // Same, from a caller buffer that is only needed during the call.
  RuntimeStatus openMemory(const void* data, size_t size, OpenError* error = nullptr);
  void close();
  bool isOpen() const { return source_ != nullptr; }

  // The queries (ndf_source.h); null when not open. The pointer lives as long as the asset is open.
  const NdfSource* source() const { return source_.get(); }

  format::AssetKind kind() const { return kind_; }
  // Registry name of the kind ("ndf-pyramid", "tensor-ndf", "glitter"; "unknown" when not open).
  const char* kindName() const;
  // The container's metadata JSON (schemas/container-metadata.schema.json: generator, canonical
  // parameters, input hashes), UTF-8, NUL-terminated; "" when not open. metadataSize() excludes the NUL.
  const char* metadataJson() const { return metadata_ ? metadata_.get() : ""; }
  size_t metadataSize() const { return metadata_size_; }

 private:
  RuntimeStatus adopt(const format::Reader& reader, std::unique_ptr<NdfSource> source, OpenError* error);

  std::unique_ptr<NdfSource> source_;
  std::unique_ptr<char[]> metadata_;
  size_t metadata_size_ = 0;
  format::AssetKind kind_ = format::AssetKind::kUnknown;
};

// openNdfAsset (ndf_source.h) that also explains a failure; error may be null.
RuntimeStatus openNdfAsset(const char* path, std::unique_ptr<NdfSource>* out, OpenError* error);
RuntimeStatus openNdfAssetMemory(const void* data, size_t size, std::unique_ptr<NdfSource>* out, OpenError* error);

}  // namespace glintbake::runtime
