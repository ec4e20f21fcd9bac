// SPDX-License-Identifier: Apache-2.0
// Shard specs, the cost-balanced assignment of units to shards and the partial writer.
#include <glintbake/bake/shard/shard.h>
#include <glintbake/format/kinds/partial.h>

#include <algorithm>
#include <cstring>
#include <numeric>

namespace glintbake::bake::shard {
namespace {

// Parses a decimal integer made of digits only (no sign, no spaces), at most 9 digits.
bool parseCount(const std::string& s, int* out) {
  if (s.empty() || s.size() > 9) return false;
  int v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  *out = v;
  return true;
}

}  // namespace

Result<ShardSpec> parseShardSpec(const std::string& text) {
  const size_t slash = text.find('/');
  ShardSpec spec;
  if (slash == std::string::npos || !parseCount(text.substr(0, slash), &spec.index) ||
      !parseCount(text.substr(slash + 1), &spec.count)) {
    return makeError(ErrorCode::kBadArgument, "--shard must be I/N (shard I of N, 0 <= I < N), got '" + text + "'");
  }
  if (spec.count < 1 || spec.count > kMaxShards)
    return makeError(ErrorCode::kBadArgument, "--shard: N must be in [1, " + std::to_string(kMaxShards) + "]");
  if (spec.index >= spec.count)
    return makeError(ErrorCode::kBadArgument, "--shard: I must be in [0, N - 1] (got " + text + ")");
  return spec;
}

std::vector<int> assignShards(const std::vector<double>& costs, int shard_count) {
  GLINTBAKE_CHECK(shard_count >= 1);
  std::vector<size_t> order(costs.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return costs[a] > costs[b]; });
  std::vector<double> load(size_t(shard_count), 0.0);
  std::vector<int> owner(costs.size(), 0);
  for (size_t u : order) {
    const size_t least = size_t(std::min_element(load.begin(), load.end()) - load.begin());
    owner[u] = int(least);
    load[least] += costs[u];
  }
  return owner;
}

PartialWriter::PartialWriter(format::Writer& writer, int zstd_level) : writer_(writer), encoder_(zstd_level) {}

BakeStatus PartialWriter::add(uint32_t type, uint64_t key, const void* data, size_t size, bool common,
                              format::Codec codec) {
  format::Codec used = format::Codec::kRaw;
  if (format::ContainerStatus st = encoder_.encode(data, size, codec, &stored_, &used);
      st != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kRuntime, std::string("cannot encode a section: ") + format::statusString(st));
  }
  format::ShardSectionHeader h;
  h.flags = common ? format::kShardSectionCommon : 0u;
  h.type = type;
  h.codec = uint32_t(used);
  h.key = key;
  h.raw_size = size;
  h.stored_size = stored_.size();
  try {
    payload_.resize(sizeof(h) + stored_.size());
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory for a shard section");
  }
  std::memcpy(payload_.data(), &h, sizeof(h));
  if (!stored_.empty()) std::memcpy(payload_.data() + sizeof(h), stored_.data(), stored_.size());
  if (format::ContainerStatus st = writer_.addSection(format::kSectionShardSection, position_, payload_.data(),
                                                      payload_.size(), format::Codec::kRaw);
      st != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, "cannot write a shard section: " + writer_.errorString(st));
  }
  // Drop large buffers rather than keep them for the writer's lifetime.
  if (payload_.capacity() > (size_t(64) << 20)) {
    std::vector<uint8_t>().swap(payload_);
    std::vector<uint8_t>().swap(stored_);
  }
  ++position_;
  ++held_;
  return okStatus();
}

}  // namespace glintbake::bake::shard
