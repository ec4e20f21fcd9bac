// Maps container reader and record-check status codes onto runtime status codes (internal to the
// runtime).
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/records.h>
#include <glintbake/runtime/runtime.h>

namespace glintbake::runtime {

inline Status fromFormatStatus(format::Status s) {
  switch (s) {
    case format::Status::kOk:
      return Status::kOk;
    case format::Status::kIoError:
      return Status::kIoError;
    case format::Status::kUnsupportedVersion:
      return Status::kUnsupportedVersion;
    default:
      return Status::kInvalidAsset;
  }
}

// A record that fails its check makes the asset invalid, except an unknown record version.
inline Status fromRecordCheck(const format::RecordCheck& check) {
  switch (check.status) {
    case format::RecordStatus::kOk:
      return Status::kOk;
    case format::RecordStatus::kUnsupportedVersion:
      return Status::kUnsupportedVersion;
    default:
      return Status::kInvalidAsset;
  }
}

}  // namespace glintbake::runtime
