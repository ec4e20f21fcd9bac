// SPDX-License-Identifier: Apache-2.0
// Exit codes of runtime-library failures when a tool opens an asset through the runtime: the
// conversion lives in exit_codes.h with those of the other layers.
#pragma once

#include <glintbake/cli/exit_codes.h>

namespace glintbake::cli {

inline int exitCodeOfRuntime(runtime::RuntimeStatus status) { return exitCodeOf(status); }

}  // namespace glintbake::cli
