// SPDX-License-Identifier: Apache-2.0
#include <glintbake/format/container.h>
#include <glintbake/format/kinds.h>
#include <glintbake/runtime/glintbake_ndf_c.h>
#include <glintbake/runtime/ndf_asset.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/version.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>

#include <new>

using glintbake::runtime::Footprint;
using glintbake::runtime::NdfSample;
using glintbake::runtime::RuntimeStatus;
using glintbake::runtime::SPoint;
using glintbake::runtime::SRect;

struct gb_ndf_asset {
  glintbake::runtime::NdfAsset asset;
  const glintbake::runtime::NdfSource* source = nullptr;  // asset.source()
  int32_t kind = 0;
};

namespace {
int32_t code(RuntimeStatus s) { return int32_t(s); }
Footprint footprint(double x, double y, double sigma) {
  Footprint f;
  f.x = x;
  f.y = y;
  f.sigma = sigma;
  return f;
}
// Opens an asset into a new handle, explaining a failure in *error when given.
template <typename Open>
int32_t openHandle(gb_ndf_asset** out, gb_open_error* error, Open open) {
  if (error) {
    error->status = GB_OK;
    error->message_id = 0;
    error->message[0] = '\0';
  }
  gb_ndf_asset* a = new (std::nothrow) gb_ndf_asset();
  if (!a) {
    if (error) {
      error->status = GB_OUT_OF_MEMORY;
      std::snprintf(error->message, sizeof(error->message), "%s", "out of memory");
    }
    return GB_OUT_OF_MEMORY;
  }
  glintbake::runtime::OpenError detail;
  const RuntimeStatus s = open(a->asset, &detail);
  if (s != RuntimeStatus::kOk) {
    delete a;
    if (error) {
      error->status = code(detail.status);
      error->message_id = detail.message_id;
      std::memcpy(error->message, detail.message, sizeof(error->message));
      error->message[sizeof(error->message) - 1] = '\0';
    }
    return code(s);
  }
  a->source = a->asset.source();
  a->kind = int32_t(a->asset.kind());
  *out = a;
  return GB_OK;
}

static_assert(sizeof(gb_open_error::message) == glintbake::runtime::OpenError::kMessageCapacity,
              "gb_open_error and OpenError hold messages of one size");

// The C kind codes are the registry's asset kinds (formats/include/glintbake/format/kinds.h).
static_assert(GB_KIND_NDF_PYRAMID == int(glintbake::format::AssetKind::kNdfPyramid) &&
                  std::string_view(glintbake::format::findKind(glintbake::format::AssetKind::kNdfPyramid)->name) ==
                      "ndf-pyramid",
              "GB_KIND_NDF_PYRAMID is the registry's ndf-pyramid");
static_assert(GB_KIND_TENSOR_NDF == int(glintbake::format::AssetKind::kTensorNdf) &&
                  std::string_view(glintbake::format::findKind(glintbake::format::AssetKind::kTensorNdf)->name) ==
                      "tensor-ndf",
              "GB_KIND_TENSOR_NDF is the registry's tensor-ndf");
static_assert(GB_KIND_WANG_TILES == int(glintbake::format::AssetKind::kWangTiles) &&
                  std::string_view(glintbake::format::findKind(glintbake::format::AssetKind::kWangTiles)->name) ==
                      "wang-tiles",
              "GB_KIND_WANG_TILES is the registry's wang-tiles");
static_assert(GB_KIND_TINY_EXAMPLE == int(glintbake::format::AssetKind::kTinyExample) &&
                  std::string_view(glintbake::format::findKind(glintbake::format::AssetKind::kTinyExample)->name) ==
                      "tiny-example",
              "GB_KIND_TINY_EXAMPLE is the registry's tiny-example");
static_assert(GB_KIND_GLITTER == int(glintbake::format::AssetKind::kGlitter) &&
                  std::string_view(glintbake::format::findKind(glintbake::format::AssetKind::kGlitter)->name) ==
                      "glitter",
              "GB_KIND_GLITTER is the registry's glitter");
}  // namespace

extern "C" {

const char* gb_status_string(int32_t status) {
  if (status < 0 || status > GB_PARTIAL_BAKE) return "unknown status";
  return glintbake::runtime::statusString(RuntimeStatus(status));
}

void gb_version(int32_t* major, int32_t* minor, int32_t* patch) {
  const glintbake::runtime::Version v = glintbake::runtime::version();
  if (major) *major = v.major;
  if (minor) *minor = v.minor;
  if (patch) *patch = v.patch;
}

const char* gb_version_string(void) { return glintbake::runtime::versionString(); }

const char* gb_kind_name(int32_t kind) {
  if (kind < 0) return "unknown";
  return glintbake::format::assetKindString(glintbake::format::AssetKind(uint32_t(kind)));
}

int32_t gb_ndf_asset_open_ex(const char* path, gb_ndf_asset** out, gb_open_error* error) {
  if (!out) return GB_INVALID_ARGUMENT;
  *out = nullptr;
  return openHandle(out, error, [&](glintbake::runtime::NdfAsset& asset, glintbake::runtime::OpenError* detail) {
    return asset.open(path, detail);
  });
}

int32_t gb_ndf_asset_open_memory_ex(const void* data, size_t size, gb_ndf_asset** out, gb_open_error* error) {
  if (!out) return GB_INVALID_ARGUMENT;
  *out = nullptr;
  return openHandle(out, error, [&](glintbake::runtime::NdfAsset& asset, glintbake::runtime::OpenError* detail) {
    return asset.openMemory(data, size, detail);
  });
}

int32_t gb_ndf_asset_open(const char* path, gb_ndf_asset** out) { return gb_ndf_asset_open_ex(path, out, nullptr); }

int32_t gb_ndf_asset_open_memory(const void* data, size_t size, gb_ndf_asset** out) {
  return gb_ndf_asset_open_memory_ex(data, size, out, nullptr);
}

int32_t gb_ndf_asset_metadata(const gb_ndf_asset* a, char* buffer, size_t capacity, size_t* length) {
  if (!a || (capacity > 0 && !buffer)) return GB_INVALID_ARGUMENT;
  const size_t n = a->asset.metadataSize();
  if (length) *length = n;
  if (capacity == 0) return GB_OK;
  const size_t copied = n < capacity ? n : capacity - 1;
  std::memcpy(buffer, a->asset.metadataJson(), copied);
  buffer[copied] = '\0';
  return copied == n ? GB_OK : GB_INVALID_ARGUMENT;
}

void gb_ndf_asset_close(gb_ndf_asset* asset) { delete asset; }

int32_t gb_ndf_asset_info(const gb_ndf_asset* a, int32_t* kind, int32_t* resolution) {
  if (!a) return GB_INVALID_ARGUMENT;
  if (kind) *kind = a->kind;
  if (resolution) *resolution = a->source->resolution();
  return GB_OK;
}

int32_t gb_ndf_asset_map(const gb_ndf_asset* a, int32_t* width, int32_t* height, int32_t* wrap) {
  if (!a) return GB_INVALID_ARGUMENT;
  const glintbake::runtime::MapSize size = a->source->mapSize();
  if (width) *width = size.width;
  if (height) *height = size.height;
  if (wrap) *wrap = int32_t(a->source->wrap());
  return GB_OK;
}

int32_t gb_ndf_asset_footprint_range(const gb_ndf_asset* a, double* exact_max, double* handover_max,
                                     double* pyramid_min, double* pyramid_max) {
  if (!a) return GB_INVALID_ARGUMENT;
  const glintbake::runtime::FootprintRange r = a->source->footprintRange();
  if (exact_max) *exact_max = r.exact_max_sigma;
  if (handover_max) *handover_max = r.handover_max_sigma;
  if (pyramid_min) *pyramid_min = r.pyramid_min_sigma;
  if (pyramid_max) *pyramid_max = r.pyramid_max_sigma;
  return GB_OK;
}

int32_t gb_ndf_asset_clustered_range(const gb_ndf_asset* a, double* clustered_min, double* clustered_max) {
  if (!a) return GB_INVALID_ARGUMENT;
  const glintbake::runtime::FootprintRange r = a->source->footprintRange();
  if (clustered_min) *clustered_min = r.clustered_min_sigma;
  if (clustered_max) *clustered_max = r.clustered_max_sigma;
  return GB_OK;
}

int32_t gb_ndf_asset_eval(const gb_ndf_asset* a, double x, double y, double sigma, double sx, double sy,
                          double* value) {
  if (!a) return GB_INVALID_ARGUMENT;
  return code(a->source->eval(footprint(x, y, sigma), SPoint{sx, sy}, value));
}

int32_t gb_ndf_asset_average(const gb_ndf_asset* a, double x, double y, double sigma, double sx0, double sy0,
                             double sx1, double sy1, double* value) {
  if (!a) return GB_INVALID_ARGUMENT;
  SRect r;
  r.x0 = sx0;
  r.y0 = sy0;
  r.x1 = sx1;
  r.y1 = sy1;
  return code(a->source->average(footprint(x, y, sigma), r, value));
}

int32_t gb_ndf_asset_sample(const gb_ndf_asset* a, double x, double y, double sigma, double u1, double u2, double* sx,
                            double* sy, double* pdf) {
  if (!a || !sx || !sy || !pdf) return GB_INVALID_ARGUMENT;
  NdfSample s;
  const RuntimeStatus st = a->source->sample(footprint(x, y, sigma), u1, u2, &s);
  if (st != RuntimeStatus::kOk) return code(st);
  *sx = s.s.x;
  *sy = s.s.y;
  *pdf = s.pdf;
  return GB_OK;
}

int32_t gb_ndf_asset_pdf(const gb_ndf_asset* a, double x, double y, double sigma, double sx, double sy, double* pdf) {
  if (!a) return GB_INVALID_ARGUMENT;
  return code(a->source->pdf(footprint(x, y, sigma), SPoint{sx, sy}, pdf));
}

int32_t gb_ndf_asset_mass(const gb_ndf_asset* a, double x, double y, double sigma, double* mass) {
  if (!a) return GB_INVALID_ARGUMENT;
  return code(a->source->mass(footprint(x, y, sigma), mass));
}

int32_t gb_ndf_asset_image(const gb_ndf_asset* a, double x, double y, double sigma, float* out, size_t count) {
  if (!a) return GB_INVALID_ARGUMENT;
  return code(a->source->image(footprint(x, y, sigma), out, count));
}

}  // extern "C"
