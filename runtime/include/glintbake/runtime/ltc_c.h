// SPDX-License-Identifier: Apache-2.0
/* C API of the runtime-lite LTC area lights (see ltc.h for the conventions).
 *
 * Status codes are those of glintbake_ndf_c.h (GB_OK = 0, ...). A table is immutable after opening;
 * lookups and integrals never allocate and may run concurrently on one handle; open and close must
 * not race with queries on the same handle. Opening is safe on untrusted files. */
#ifndef GLINTBAKE_LTC_C_H
#define GLINTBAKE_LTC_C_H

#include <stddef.h>
#include <stdint.h>

#include <glintbake/runtime/c_api.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One looked-up LTC: row-major inverse matrix (normalised by its middle element) and magnitudes. */
typedef struct gb_ltc {
  float inv_m[9];
  float norm;    /* integral of BRDF * cos (Fresnel = 1) */
  float fresnel; /* the same weighted by (1 - V.H)^5 */
} gb_ltc;

typedef struct gb_ltc_table gb_ltc_table;

GLINTBAKE_C_API int32_t gb_ltc_table_open(const char* path, gb_ltc_table** out);
GLINTBAKE_C_API int32_t gb_ltc_table_open_memory(const void* data, size_t size, gb_ltc_table** out);
/* Adopts two size x size x 4 float arrays in the published layout (copied). */
GLINTBAKE_C_API int32_t gb_ltc_table_from_arrays(int32_t size, const float* ltc1, const float* ltc2, gb_ltc_table** out);
GLINTBAKE_C_API void gb_ltc_table_close(gb_ltc_table* table); /* NULL is allowed */
GLINTBAKE_C_API int32_t gb_ltc_table_size(const gb_ltc_table* table, int32_t* size);

/* Bilinear lookup: roughness in [0, 1] (sqrt of alpha_GGX), cos_theta_v in [0, 1] (clamped). */
GLINTBAKE_C_API int32_t gb_ltc_lookup(const gb_ltc_table* table, float roughness, float cos_theta_v, gb_ltc* out);

/* Integral of the LTC (without magnitude) over a polygon: `count` vertices (3..16) as x, y, z
 * triples relative to the shading point in the shading frame (z = normal, x towards the view
 * vector), wound so that (v1 - v0) x (v2 - v0) points away from the shading point. */
GLINTBAKE_C_API int32_t gb_ltc_integrate_polygon(const gb_ltc* ltc, const float* vertices, int32_t count, int32_t two_sided,
                                 float* out);

/* f0 * norm + (1 - f0) * fresnel: the magnitude with Schlick Fresnel. */
GLINTBAKE_C_API float gb_ltc_fresnel_magnitude(const gb_ltc* ltc, float f0);

#ifdef __cplusplus
}
#endif

#endif /* GLINTBAKE_LTC_C_H */
