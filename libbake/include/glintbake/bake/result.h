// SPDX-License-Identifier: Apache-2.0
// Error reporting of the baking library: functions that can fail on input data return
// Result<T> (a value or an Error); programmer errors are caught by GLINTBAKE_CHECK.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <variant>

namespace glintbake::bake {

// Error categories. The numeric values equal the tools' exit codes (README, "Exit codes").
enum class ErrorCode : int {
  kBadArgument = 1,   // a parameter out of its documented range
  kIo = 2,            // a file cannot be opened, read or written
  kInvalidInput = 3,  // malformed, corrupt or non-finite input data
  kRuntime = 4,       // the computation failed
  kUnsupported = 5,   // valid but unsupported input
};

struct Error {
  ErrorCode code = ErrorCode::kRuntime;
  std::string message;  // one line, names the problem (and the file, by the name it was given)
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT: implicit by design
  Result(Error error) : v_(std::move(error)) {}  // NOLINT
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

// Result<void>
struct Ok {};
using BakeStatus = Result<Ok>;
inline BakeStatus okStatus() { return Ok{}; }

inline Error makeError(ErrorCode code, std::string message) { return Error{code, std::move(message)}; }

}  // namespace glintbake::bake

// Aborts with file:line on a violated internal invariant (never on bad input data).
#define GLINTBAKE_CHECK(cond)                                                                \
  do {                                                                                       \
    if (!(cond)) {                                                                           \
      std::fprintf(stderr, "%s:%d: internal check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                          \
    }                                                                                        \
  } while (0)
#ifndef NDEBUG
#define GLINTBAKE_DCHECK(cond) GLINTBAKE_CHECK(cond)
#else
#define GLINTBAKE_DCHECK(cond) \
  do {                         \
  } while (0)
#endif
