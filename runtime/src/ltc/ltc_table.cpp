// SPDX-License-Identifier: Apache-2.0
// Runtime-lite LTC table: loading an ltc-table container and bilinear lookups.
#include <glintbake/format/container.h>
#include <glintbake/runtime/ltc.h>
#include "../format_status.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace glintbake::runtime {

namespace {

constexpr int kMaxTableSize = 1024;
constexpr uint32_t kLtcTableSection = format::kSectionLtcTable;

// Reads section (48, key) and checks it is an N x N x 4 image; *size is set by the first call and
// must match in the second.
RuntimeStatus readImage(const format::Reader& reader, uint64_t key, int* size, std::vector<float>* out) {
  const int index = reader.find(kLtcTableSection, key);
  if (index < 0) return RuntimeStatus::kInvalidAsset;
  const format::SectionInfo& info = reader.sections()[size_t(index)];
  if (info.raw_size < sizeof(format::ImageSectionHeader)) return RuntimeStatus::kInvalidAsset;
  format::ImageSectionHeader header;
  std::vector<uint8_t> bytes;
  if (info.raw_size > uint64_t(sizeof(header)) + uint64_t(kMaxTableSize) * kMaxTableSize * 16)
    return RuntimeStatus::kInvalidAsset;
  const format::ContainerStatus read = reader.readSection(size_t(index), &bytes);
  if (read != format::ContainerStatus::kOk) return fromFormatStatus(read);
  // The layout is little-endian; this reader assumes a little-endian host.
  std::memcpy(&header, bytes.data(), sizeof(header));
  if (header.magic != format::ImageSectionHeader{}.magic || header.channels != 4 || header.layers != 1 ||
      header.width != header.height || header.width < 2 || header.width > uint32_t(kMaxTableSize))
    return RuntimeStatus::kInvalidAsset;
  const int n = int(header.width);
  if (*size != 0 && *size != n) return RuntimeStatus::kInvalidAsset;
  const size_t count = size_t(n) * size_t(n) * 4;
  if (bytes.size() != sizeof(header) + count * sizeof(float)) return RuntimeStatus::kInvalidAsset;
  out->resize(count);
  std::memcpy(out->data(), bytes.data() + sizeof(header), count * sizeof(float));
  for (float value : *out)
    if (!std::isfinite(value)) return RuntimeStatus::kInvalidAsset;
  *size = n;
  return RuntimeStatus::kOk;
}

RuntimeStatus load(format::Reader& reader, LtcTable* table) {
  if (reader.kind() == format::AssetKind::kPartial) return RuntimeStatus::kPartialBake;
  if (reader.kind() != format::AssetKind::kLtcTable) return RuntimeStatus::kWrongKind;
  int size = 0;
  std::vector<float> ltc1, ltc2;
  RuntimeStatus status = readImage(reader, 0, &size, &ltc1);
  if (status != RuntimeStatus::kOk) return status;
  status = readImage(reader, 1, &size, &ltc2);
  if (status != RuntimeStatus::kOk) return status;
  return table->fromArrays(size, ltc1.data(), ltc2.data());
}

// Bilinear weights of a coordinate in [0, n-1].
struct Lerp {
  int i0, i1;
  float w;
};
Lerp lerpAt(float x, int n) {
  x = std::clamp(x, 0.0f, float(n - 1));
  const int i0 = std::min(int(x), n - 2);
  return {i0, i0 + 1, x - float(i0)};
}

}  // namespace

RuntimeStatus LtcTable::open(const char* path) {
  if (!path) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  const format::ContainerStatus status = reader.open(path);
  if (status != format::ContainerStatus::kOk) return fromFormatStatus(status);
  return load(reader, this);
}

RuntimeStatus LtcTable::openMemory(const void* data, size_t size) {
  if (!data) return RuntimeStatus::kInvalidArgument;
  format::Reader reader;
  const format::ContainerStatus status = reader.openMemory(data, size);
  if (status != format::ContainerStatus::kOk) return fromFormatStatus(status);
  return load(reader, this);
}

RuntimeStatus LtcTable::fromArrays(int size, const float* ltc1, const float* ltc2) {
  if (size < 2 || size > kMaxTableSize || !ltc1 || !ltc2) return RuntimeStatus::kInvalidArgument;
  const size_t count = size_t(size) * size_t(size) * 4;
  for (size_t i = 0; i < count; ++i)
    if (!std::isfinite(ltc1[i]) || !std::isfinite(ltc2[i])) return RuntimeStatus::kInvalidArgument;
  ltc1_.assign(ltc1, ltc1 + count);
  ltc2_.assign(ltc2, ltc2 + count);
  size_ = size;
  return RuntimeStatus::kOk;
}

RuntimeStatus LtcTable::lookup(float roughness, float cos_theta_v, LtcCoefficients* out) const {
  if (size_ == 0 || !out || !std::isfinite(roughness) || !std::isfinite(cos_theta_v))
    return RuntimeStatus::kInvalidArgument;
  const float n1 = float(size_ - 1);
  const Lerp la = lerpAt(std::clamp(roughness, 0.0f, 1.0f) * n1, size_);
  const Lerp lt = lerpAt(std::sqrt(1.0f - std::clamp(cos_theta_v, 0.0f, 1.0f)) * n1, size_);
  float t1[4] = {0, 0, 0, 0}, t2[4] = {0, 0, 0, 0};
  const int as[2] = {la.i0, la.i1};
  const int ts[2] = {lt.i0, lt.i1};
  const float wa[2] = {1.0f - la.w, la.w};
  const float wt[2] = {1.0f - lt.w, lt.w};
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const float w = wa[i] * wt[j];
      const size_t index = (size_t(as[i]) + size_t(size_) * size_t(ts[j])) * 4;
      for (int c = 0; c < 4; ++c) {
        t1[c] += w * ltc1_[index + size_t(c)];
        t2[c] += w * ltc2_[index + size_t(c)];
      }
    }
  }
  // ltc_1 = (m00, m20, m02, m22) of the normalised inverse matrix.
  *out = LtcCoefficients{};
  out->inv_m[0][0] = t1[0];
  out->inv_m[2][0] = t1[1];
  out->inv_m[0][2] = t1[2];
  out->inv_m[2][2] = t1[3];
  out->norm = t2[0];
  out->fresnel = t2[1];
  out->sphere = t2[3];
  return RuntimeStatus::kOk;
}

float LtcTable::sphereFactor(float z, float len) const {
  if (size_ == 0 || !std::isfinite(z) || !std::isfinite(len)) return 0.0f;
  const float n1 = float(size_ - 1);
  const Lerp li = lerpAt((std::clamp(z, -1.0f, 1.0f) * 0.5f + 0.5f) * n1, size_);
  const Lerp lj = lerpAt(std::clamp(len, 0.0f, 1.0f) * n1, size_);
  auto at = [&](int i, int j) { return ltc2_[(size_t(i) + size_t(size_) * size_t(j)) * 4 + 3]; };
  return (1.0f - lj.w) * ((1.0f - li.w) * at(li.i0, lj.i0) + li.w * at(li.i1, lj.i0)) +
         lj.w * ((1.0f - li.w) * at(li.i0, lj.i1) + li.w * at(li.i1, lj.i1));
}

}  // namespace glintbake::runtime
