// SPDX-License-Identifier: Apache-2.0
// C API of the runtime-lite LTC area lights.
#include <glintbake/runtime/ltc.h>
#include <glintbake/runtime/ltc_c.h>

#include <new>

using glintbake::runtime::LtcCoefficients;
using glintbake::runtime::LtcTable;
using glintbake::runtime::RuntimeStatus;

struct gb_ltc_table {
  LtcTable table;
};

namespace {

template <typename Open>
int32_t openWith(gb_ltc_table** out, Open&& open) {
  if (!out) return int32_t(RuntimeStatus::kInvalidArgument);
  *out = nullptr;
  auto* handle = new (std::nothrow) gb_ltc_table;
  if (!handle) return int32_t(RuntimeStatus::kOutOfMemory);
  const RuntimeStatus status = open(handle->table);
  if (status != RuntimeStatus::kOk) {
    delete handle;
    return int32_t(status);
  }
  *out = handle;
  return int32_t(RuntimeStatus::kOk);
}

LtcCoefficients fromC(const gb_ltc& ltc) {
  LtcCoefficients c;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.inv_m[r][k] = ltc.inv_m[3 * r + k];
  c.norm = ltc.norm;
  c.fresnel = ltc.fresnel;
  return c;
}

}  // namespace

extern "C" {

int32_t gb_ltc_table_open(const char* path, gb_ltc_table** out) {
  return openWith(out, [&](LtcTable& table) { return table.open(path); });
}

int32_t gb_ltc_table_open_memory(const void* data, size_t size, gb_ltc_table** out) {
  return openWith(out, [&](LtcTable& table) { return table.openMemory(data, size); });
}

int32_t gb_ltc_table_from_arrays(int32_t size, const float* ltc1, const float* ltc2, gb_ltc_table** out) {
  return openWith(out, [&](LtcTable& table) { return table.fromArrays(size, ltc1, ltc2); });
}

void gb_ltc_table_close(gb_ltc_table* table) { delete table; }

int32_t gb_ltc_table_size(const gb_ltc_table* table, int32_t* size) {
  if (!table || !size) return int32_t(RuntimeStatus::kInvalidArgument);
  *size = table->table.size();
  return int32_t(RuntimeStatus::kOk);
}

int32_t gb_ltc_lookup(const gb_ltc_table* table, float roughness, float cos_theta_v, gb_ltc* out) {
  if (!table || !out) return int32_t(RuntimeStatus::kInvalidArgument);
  LtcCoefficients c;
  const RuntimeStatus status = table->table.lookup(roughness, cos_theta_v, &c);
  if (status != RuntimeStatus::kOk) return int32_t(status);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) out->inv_m[3 * r + k] = c.inv_m[r][k];
  out->norm = c.norm;
  out->fresnel = c.fresnel;
  return int32_t(RuntimeStatus::kOk);
}

int32_t gb_ltc_integrate_polygon(const gb_ltc* ltc, const float* vertices, int32_t count, int32_t two_sided,
                                 float* out) {
  if (!ltc || !vertices || !out || count < 3 || count > glintbake::runtime::kLtcMaxPolygonVertices)
    return int32_t(RuntimeStatus::kInvalidArgument);
  *out = glintbake::runtime::ltcIntegratePolygon(fromC(*ltc), reinterpret_cast<const float(*)[3]>(vertices), count,
                                                 two_sided != 0);
  return int32_t(RuntimeStatus::kOk);
}

float gb_ltc_fresnel_magnitude(const gb_ltc* ltc, float f0) {
  return ltc ? f0 * ltc->norm + (1.0f - f0) * ltc->fresnel : 0.0f;
}

}  // extern "C"
