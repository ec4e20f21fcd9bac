// SPDX-License-Identifier: Apache-2.0
// What the record checks of formats/include/glintbake/format/kinds/*.h report: one status type for
// every kind's records, and the text of the rule that failed.
#pragma once

#include <cstdint>

namespace glintbake::format {

enum class RecordStatus : int32_t {
  kOk = 0,
  kBadMagic = 1,            // the record's magic is wrong (not this record)
  kUnsupportedVersion = 2,  // a record version this library does not know
  kInvalid = 3,             // a field out of range, or fields that disagree (the detail says which)
};

// Stable text of a record status ("ok", "bad magic", ...). Never returns null.
const char* recordStatusString(RecordStatus status);

// The outcome of one record check: the status and, unless kOk, a short static description of the
// rule that failed ("NDF resolution out of range", ...), for messages. detail is never null.
struct RecordCheck {
  RecordStatus status = RecordStatus::kOk;
  const char* detail = "";
  explicit operator bool() const { return status == RecordStatus::kOk; }
};

constexpr RecordCheck recordOk() { return RecordCheck{}; }
constexpr RecordCheck recordInvalid(const char* detail) { return RecordCheck{RecordStatus::kInvalid, detail}; }

}  // namespace glintbake::format
