// SPDX-License-Identifier: Apache-2.0
// Exit codes (tool.h: kExit*) of the libraries' results, one conversion per layer, and the two
// helpers every command uses to turn a failed bake result into a cli::Error.
#pragma once

#include <glintbake/bake/result.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>
#include <glintbake/runtime/runtime.h>

#include <string>
#include <utility>

namespace glintbake::cli {

// libbake error categories share the exit-code numbering (1 bad argument ... 5 unsupported).
inline int exitCodeOf(bake::ErrorCode code) { return int(code); }
inline int exitCodeOf(const bake::Error& error) { return exitCodeOf(error.code); }

// Container reads: kIoError -> 2, kUnsupportedVersion -> 5, kInvalidArgument and kNotFound -> 1,
// anything else (a corrupt or foreign file) -> 3.
inline int exitCodeOf(format::ContainerStatus status) {
  switch (status) {
    case format::ContainerStatus::kOk:
      return kExitOk;
    case format::ContainerStatus::kIoError:
      return kExitIo;
    case format::ContainerStatus::kUnsupportedVersion:
      return kExitUnsupported;
    case format::ContainerStatus::kInvalidArgument:
    case format::ContainerStatus::kNotFound:
      return kExitBadArguments;
    default:
      return kExitInvalidInput;
  }
}

// Runtime opens: kIoError -> 2, kWrongKind, kPartialBake and kUnsupportedVersion -> 5, kOutOfMemory -> 4,
// anything else (malformed asset) -> 3.
inline int exitCodeOf(runtime::RuntimeStatus status) {
  switch (status) {
    case runtime::RuntimeStatus::kOk:
      return kExitOk;
    case runtime::RuntimeStatus::kIoError:
      return kExitIo;
    case runtime::RuntimeStatus::kWrongKind:
    case runtime::RuntimeStatus::kPartialBake:
    case runtime::RuntimeStatus::kUnsupportedVersion:
      return kExitUnsupported;
    case runtime::RuntimeStatus::kOutOfMemory:
      return kExitRuntime;
    default:
      return kExitInvalidInput;
  }
}

// Throws cli::Error with the error's exit code and message (prefixed by `context` when given)
// if the result failed; unwrap returns the value otherwise.
inline void check(const bake::BakeStatus& status, const std::string& context = "") {
  if (!status.ok()) throw Error(exitCodeOf(status.error()), context + status.error().message);
}
template <typename T>
T unwrap(bake::Result<T> result, const std::string& context = "") {
  if (!result.ok()) throw Error(exitCodeOf(result.error()), context + result.error().message);
  return std::move(result).value();
}

}  // namespace glintbake::cli
