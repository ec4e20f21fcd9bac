// SPDX-License-Identifier: Apache-2.0
// Incremental XXH3-64 (for the whole-file checksum, which the writer computes while streaming
// sections out and the reader verifies in chunks). Private to the container library.
#pragma once

#include <cstddef>
#include <cstdint>

namespace glintbake::format::detail {

class XXH3Streamer {
 public:
  XXH3Streamer();
  ~XXH3Streamer();
  XXH3Streamer(const XXH3Streamer&) = delete;
  XXH3Streamer& operator=(const XXH3Streamer&) = delete;
  // False if the hash state could not be allocated (every other call is then a no-op).
  bool ok() const { return state_ != nullptr; }
  void reset();
  void update(const void* data, size_t size);
  // XXH3-64 of every byte passed to update() since construction or reset(); equals hash64() of
  // their concatenation.
  uint64_t digest() const;

 private:
  void* state_;  // XXH3_state_t, opaque here to keep xxhash.h out of the other sources
};

}  // namespace glintbake::format::detail
