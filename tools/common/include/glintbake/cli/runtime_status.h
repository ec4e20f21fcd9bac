// Exit codes of runtime-library failures when a tool opens an asset through the runtime.
#pragma once

#include <glintbake/cli/tool.h>
#include <glintbake/runtime/runtime.h>

namespace glintbake::cli {

// kIoError -> 2, kWrongKind and kUnsupportedVersion -> 5, kOutOfMemory -> 4, anything else
// (malformed asset) -> 3.
inline int exitCodeOfRuntime(runtime::Status status) {
  switch (status) {
    case runtime::Status::kIoError:
      return kExitIo;
    case runtime::Status::kWrongKind:
    case runtime::Status::kUnsupportedVersion:
      return kExitUnsupported;
    case runtime::Status::kOutOfMemory:
      return kExitRuntime;
    default:
      return kExitInvalidInput;
  }
}

}  // namespace glintbake::cli
