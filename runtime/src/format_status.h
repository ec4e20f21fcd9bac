// Maps container reader status codes onto runtime status codes (internal to the runtime).
#pragma once

#include <glintbake/format/container.h>
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

}  // namespace glintbake::runtime
