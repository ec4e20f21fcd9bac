// SPDX-License-Identifier: Apache-2.0
#include <glintbake/runtime/runtime.h>

namespace glintbake::runtime {

const char* statusString(RuntimeStatus status) {
  switch (status) {
    case RuntimeStatus::kOk:
      return "ok";
    case RuntimeStatus::kIoError:
      return "i/o error";
    case RuntimeStatus::kInvalidAsset:
      return "invalid asset";
    case RuntimeStatus::kWrongKind:
      return "asset kind not handled by this reader";
    case RuntimeStatus::kUnsupportedVersion:
      return "unsupported container version";
    case RuntimeStatus::kInvalidArgument:
      return "invalid argument";
    case RuntimeStatus::kOutOfMemory:
      return "out of memory";
    case RuntimeStatus::kPartialBake:
      return "a partial bake (one shard), not an asset: join the shards with glintinfo merge";
  }
  return "unknown status";
}

}  // namespace glintbake::runtime
