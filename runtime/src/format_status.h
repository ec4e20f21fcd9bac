// SPDX-License-Identifier: Apache-2.0
// Maps container reader and record-check status codes onto runtime status codes (internal to the
// runtime).
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/records.h>
#include <glintbake/runtime/runtime.h>

#include <cstddef>
#include <cstdint>

namespace glintbake::runtime {

inline RuntimeStatus fromFormatStatus(format::ContainerStatus s) {
  switch (s) {
    case format::ContainerStatus::kOk:
      return RuntimeStatus::kOk;
    case format::ContainerStatus::kIoError:
      return RuntimeStatus::kIoError;
    case format::ContainerStatus::kUnsupportedVersion:
      return RuntimeStatus::kUnsupportedVersion;
    default:
      return RuntimeStatus::kInvalidAsset;
  }
}

// A record that fails its check makes the asset invalid, except an unknown record version.
inline RuntimeStatus fromRecordCheck(const format::RecordCheck& check) {
  switch (check.status) {
    case format::RecordStatus::kOk:
      return RuntimeStatus::kOk;
    case format::RecordStatus::kUnsupportedVersion:
      return RuntimeStatus::kUnsupportedVersion;
    default:
      return RuntimeStatus::kInvalidAsset;
  }
}

// Reads section (type, key 0) into a caller buffer of exactly `size` bytes: an asset whose section
// is missing or of another size is invalid.
inline RuntimeStatus readSectionExact(const format::Reader& reader, uint32_t type, void* out, size_t size) {
  const int idx = reader.find(type, 0);
  if (idx < 0 || reader.sections()[size_t(idx)].raw_size != size) return RuntimeStatus::kInvalidAsset;
  return fromFormatStatus(reader.readSectionInto(size_t(idx), out, size));
}

}  // namespace glintbake::runtime
