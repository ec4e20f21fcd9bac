#include <glintbake/runtime/runtime.h>

namespace glintbake::runtime {

const char* statusString(Status status) {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kIoError:
      return "i/o error";
    case Status::kInvalidAsset:
      return "invalid asset";
    case Status::kWrongKind:
      return "asset kind not handled by this reader";
    case Status::kUnsupportedVersion:
      return "unsupported container version";
    case Status::kInvalidArgument:
      return "invalid argument";
    case Status::kOutOfMemory:
      return "out of memory";
  }
  return "unknown status";
}

}  // namespace glintbake::runtime
