// SPDX-License-Identifier: Apache-2.0
// Maps container reader and record-check status codes onto runtime status codes (internal to the
// runtime).
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/records.h>
#include <glintbake/runtime/runtime.h>

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

}  // namespace glintbake::runtime
