// SPDX-License-Identifier: Apache-2.0
// Content hashes: XXH3-64 for checksums, XXH3-128 for provenance (Collet, xxHash, XXH3 variant).
#include <glintbake/format/container.h>

#include "hash_stream.h"

#include <xxhash.h>

#include <cstdio>
#include <string>
#include <vector>

namespace glintbake::format {

uint64_t hash64(const void* data, size_t size) { return XXH3_64bits(data, size); }

namespace {

// Text form "xxh3-128:" + the 16 bytes of XXH128_canonical_t (high half first) as lowercase hex.
std::string canonicalHex(XXH128_hash_t hash) {
  XXH128_canonical_t canonical;
  XXH128_canonicalFromHash(&canonical, hash);
  static const char* kDigits = "0123456789abcdef";
  std::string hex = "xxh3-128:";
  hex.reserve(9 + 32);
  for (unsigned char byte : canonical.digest) {
    hex += kDigits[byte >> 4];
    hex += kDigits[byte & 0xF];
  }
  return hex;
}

}  // namespace

std::string hash128Hex(const void* data, size_t size) { return canonicalHex(XXH3_128bits(data, size)); }

ContainerStatus hashFile128Hex(const std::string& path, std::string* hex_out) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return ContainerStatus::kIoError;
  XXH3_state_t* state = XXH3_createState();
  if (!state) {
    std::fclose(file);
    return ContainerStatus::kIoError;
  }
  XXH3_128bits_reset(state);
  std::vector<unsigned char> chunk(size_t(1) << 20);
  bool ok = true;
  for (;;) {
    const size_t n = std::fread(chunk.data(), 1, chunk.size(), file);
    if (n > 0) XXH3_128bits_update(state, chunk.data(), n);
    if (n < chunk.size()) {
      ok = !std::ferror(file);
      break;
    }
  }
  std::fclose(file);
  if (ok && hex_out) *hex_out = canonicalHex(XXH3_128bits_digest(state));
  XXH3_freeState(state);
  return ok ? ContainerStatus::kOk : ContainerStatus::kIoError;
}

namespace detail {

XXH3Streamer::XXH3Streamer() : state_(XXH3_createState()) { reset(); }

XXH3Streamer::~XXH3Streamer() { XXH3_freeState(static_cast<XXH3_state_t*>(state_)); }

void XXH3Streamer::reset() {
  if (state_) XXH3_64bits_reset(static_cast<XXH3_state_t*>(state_));
}

void XXH3Streamer::update(const void* data, size_t size) {
  if (state_ && size != 0) XXH3_64bits_update(static_cast<XXH3_state_t*>(state_), data, size);
}

uint64_t XXH3Streamer::digest() const {
  return state_ ? XXH3_64bits_digest(static_cast<const XXH3_state_t*>(state_)) : 0;
}

}  // namespace detail
}  // namespace glintbake::format
