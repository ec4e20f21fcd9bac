// SPDX-License-Identifier: Apache-2.0
/* C API of the glintbake runtime-lite's NDF assets (ndf-pyramid, tensor-ndf, behind one handle),
 * for engines that do not link C++ directly. The BRDF and LTC C APIs are glintbake_brdf_c.h and
 * ltc_c.h; they share the status codes below.
 *
 * Every function returns a status code (GB_OK = 0; the values equal glintbake::runtime::RuntimeStatus)
 * and writes results through out-parameters. Positions and sigma are in texels of the source normal
 * map (texel centres at +0.5, y downwards); s-plane points are (s_x, s_y) of the projected
 * hemisphere, values are densities per unit s-plane area. Query functions never allocate and may be
 * called concurrently on one handle; open and close must not race with queries on the same handle.
 * Opening is safe on untrusted files. */
#ifndef GLINTBAKE_NDF_C_H
#define GLINTBAKE_NDF_C_H

#include <stddef.h>
#include <stdint.h>

#include <glintbake/runtime/c_api.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
  GB_OK = 0,
  GB_IO_ERROR = 1,
  GB_INVALID_ASSET = 2,
  GB_WRONG_KIND = 3,
  GB_UNSUPPORTED_VERSION = 4,
  GB_INVALID_ARGUMENT = 5,
  GB_OUT_OF_MEMORY = 6,
  GB_PARTIAL_BAKE = 7 /* one shard of a sharded bake: join the shards with glintinfo merge */
};

/* Stable text of a status code; never NULL. */
GLINTBAKE_C_API const char* gb_status_string(int32_t status);

/* The version of the runtime library linked (GLINTBAKE_VERSION_* in glintbake/version.h are those
 * of the headers compiled against). Any pointer may be NULL. */
GLINTBAKE_C_API void gb_version(int32_t* major, int32_t* minor, int32_t* patch);
/* "major.minor.patch"; static, never NULL. */
GLINTBAKE_C_API const char* gb_version_string(void);

/* Any NDF asset kind the runtime reads (ndf-pyramid, tensor-ndf, glitter, tiny-example), behind one handle. The queries
 * follow ndf_source.h: blended P-NDF values >= 0, averages over s-rectangles, importance
 * samples whose pdf equals gb_ndf_asset_pdf at the sampled point bit for bit. */
typedef struct gb_ndf_asset gb_ndf_asset;

/* Container asset kinds of NDF assets (formats/SPEC.md section 4; the values of the kind registry,
 * glintbake/format/kinds.h). */
enum {
  GB_KIND_NDF_PYRAMID = 1,
  GB_KIND_TENSOR_NDF = 2,
  GB_KIND_WANG_TILES = 5,
  GB_KIND_TINY_EXAMPLE = 6,
  GB_KIND_GLITTER = 7
};

/* GB_WRONG_KIND for containers of other asset kinds. */
GLINTBAKE_C_API int32_t gb_ndf_asset_open(const char* path, gb_ndf_asset** out);
GLINTBAKE_C_API int32_t gb_ndf_asset_open_memory(const void* data, size_t size, gb_ndf_asset** out);

/* Why an open failed: the status returned, the validator's stable message id of the first error it
 * finds in the file (formats/SPEC.md "Validation": 1xxx I/O, 2xxx header, 3xxx index, 4xxx payloads,
 * 5xxx metadata, 6xxx kind records; e.g. 4001 a section checksum differs), and its one-line text.
 * message_id is 0 when the container is sound and the runtime refused it for another reason (a
 * container of another kind, ...), which message then states. message is NUL-terminated. */
typedef struct gb_open_error {
  int32_t status;
  int32_t message_id;
  char message[256];
} gb_open_error;

/* gb_ndf_asset_open / _open_memory that also explain a failure in *error (may be NULL; cleared on
 * success). Explaining re-reads the file with the validator, so failures cost a full read. */
GLINTBAKE_C_API int32_t gb_ndf_asset_open_ex(const char* path, gb_ndf_asset** out, gb_open_error* error);
GLINTBAKE_C_API int32_t gb_ndf_asset_open_memory_ex(const void* data, size_t size, gb_ndf_asset** out,
                                                    gb_open_error* error);
GLINTBAKE_C_API void gb_ndf_asset_close(gb_ndf_asset* asset); /* NULL is allowed */

/* Asset kind (GB_KIND_*) and NDF resolution R (bins per side); either pointer may be NULL. */
GLINTBAKE_C_API int32_t gb_ndf_asset_info(const gb_ndf_asset* asset, int32_t* kind, int32_t* resolution);

/* Registry name of an asset kind code ("ndf-pyramid", "tensor-ndf", "glitter", ...; "unknown"
 * for codes it does not know); never NULL. */
GLINTBAKE_C_API const char* gb_kind_name(int32_t kind);

/* The container's metadata JSON (UTF-8; schemas/container-metadata.schema.json). Copies at most
 * capacity - 1 bytes and a NUL into buffer (buffer may be NULL when capacity is 0) and sets
 * *length (may be NULL) to the full length without the NUL, so a first call with capacity 0 sizes
 * the buffer. GB_INVALID_ARGUMENT when the text did not fit (buffer then holds the truncated
 * prefix). */
GLINTBAKE_C_API int32_t gb_ndf_asset_metadata(const gb_ndf_asset* asset, char* buffer, size_t capacity, size_t* length);

/* Source map size in texels and wrap mode (0 repeat, 1 clamp, 2
 * unbounded: Wang tiles and tiny examples cover the plane without a period, pass positions as they are); any pointer
 * may be NULL. */
GLINTBAKE_C_API int32_t gb_ndf_asset_map(const gb_ndf_asset* asset, int32_t* width, int32_t* height, int32_t* wrap);

/* The footprint std (texels) each path answers (ndf_source.h, FootprintRange): exact from the
 * flakes for sigma <= exact_max (0: no flakes), blended into the pyramid up to handover_max, the
 * pyramid's levels from pyramid_min to pyramid_max. Any pointer may be NULL. */
GLINTBAKE_C_API int32_t gb_ndf_asset_footprint_range(const gb_ndf_asset* asset, double* exact_max, double* handover_max,
                                                     double* pyramid_min, double* pyramid_max);

/* The footprints the clustered lobes answer alone (both 0: no clustered path); the flakes hand over
 * to them from exact_max, and they to the pyramid up to handover_max. Any pointer may be NULL. */
GLINTBAKE_C_API int32_t gb_ndf_asset_clustered_range(const gb_ndf_asset* asset, double* clustered_min,
                                                     double* clustered_max);

GLINTBAKE_C_API int32_t gb_ndf_asset_eval(const gb_ndf_asset* asset, double x, double y, double sigma, double sx,
                                          double sy, double* value);
GLINTBAKE_C_API int32_t gb_ndf_asset_average(const gb_ndf_asset* asset, double x, double y, double sigma, double sx0,
                                             double sy0, double sx1, double sy1, double* value);
GLINTBAKE_C_API int32_t gb_ndf_asset_sample(const gb_ndf_asset* asset, double x, double y, double sigma, double u1,
                                            double u2, double* sx, double* sy, double* pdf);
GLINTBAKE_C_API int32_t gb_ndf_asset_pdf(const gb_ndf_asset* asset, double x, double y, double sigma, double sx,
                                         double sy, double* pdf);
/* Integral of the footprint's NDF over the s-plane (what sampling normalises by). */
GLINTBAKE_C_API int32_t gb_ndf_asset_mass(const gb_ndf_asset* asset, double x, double y, double sigma, double* mass);
GLINTBAKE_C_API int32_t gb_ndf_asset_image(const gb_ndf_asset* asset, double x, double y, double sigma, float* out,
                                           size_t count);

#ifdef __cplusplus
}
#endif

#endif /* GLINTBAKE_NDF_C_H */
