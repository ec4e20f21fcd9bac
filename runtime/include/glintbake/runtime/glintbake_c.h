/* C API of the glintbake runtime-lite, for engines that do not link C++ directly.
 *
 * Every function returns a status code (GB_OK = 0; the values equal glintbake::runtime::Status)
 * and writes results through out-parameters. Positions and sigma are in texels of the source normal
 * map (texel centres at +0.5, y downwards); s-plane points are (s_x, s_y) of the projected
 * hemisphere, values are densities per unit s-plane area. Query functions never allocate and may be
 * called concurrently on one handle; open and close must not race with queries on the same handle.
 * Opening is safe on untrusted files. */
#ifndef GLINTBAKE_C_H
#define GLINTBAKE_C_H

#include <stddef.h>
#include <stdint.h>

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
  GB_OUT_OF_MEMORY = 6
};

/* Stable text of a status code; never NULL. */
const char* gb_status_string(int32_t status);

/* An opened ndf-pyramid asset (all images in memory, see ndf_pyramid.h). */
typedef struct gb_ndf_pyramid gb_ndf_pyramid;

int32_t gb_ndf_pyramid_open(const char* path, gb_ndf_pyramid** out);
int32_t gb_ndf_pyramid_open_memory(const void* data, size_t size, gb_ndf_pyramid** out);
void gb_ndf_pyramid_close(gb_ndf_pyramid* pyramid); /* NULL is allowed */

/* NDF resolution R (bins per side) and level count. */
int32_t gb_ndf_pyramid_info(const gb_ndf_pyramid* pyramid, int32_t* resolution, int32_t* levels);

/* Trilinearly interpolated P-NDF value at s for the footprint (x, y, sigma). */
int32_t gb_ndf_pyramid_eval(const gb_ndf_pyramid* pyramid, double x, double y, double sigma, double sx, double sy,
                            double* value);
/* Average over the s-rectangle [sx0, sx1] x [sy0, sy1]. */
int32_t gb_ndf_pyramid_average(const gb_ndf_pyramid* pyramid, double x, double y, double sigma, double sx0, double sy0,
                               double sx1, double sy1, double* value);
/* Importance sample from two uniforms in [0, 1); *pdf equals gb_ndf_pyramid_pdf at (*sx, *sy). */
int32_t gb_ndf_pyramid_sample(const gb_ndf_pyramid* pyramid, double x, double y, double sigma, double u1, double u2,
                              double* sx, double* sy, double* pdf);
int32_t gb_ndf_pyramid_pdf(const gb_ndf_pyramid* pyramid, double x, double y, double sigma, double sx, double sy,
                           double* pdf);
/* The blended R x R image (row 0 at s_y = +1); out must hold count >= R * R floats. */
int32_t gb_ndf_pyramid_image(const gb_ndf_pyramid* pyramid, double x, double y, double sigma, float* out, size_t count);

/* Any NDF asset kind the runtime reads (ndf-pyramid, tensor-ndf), behind one handle; the queries
 * behave as the gb_ndf_pyramid_* ones (ndf_source.h states the shared contract: values >= 0, the
 * pdf returned by sampling equals gb_ndf_asset_pdf at the sampled point bit for bit). */
typedef struct gb_ndf_asset gb_ndf_asset;

/* Container asset kinds of NDF assets (formats/SPEC.md section 4). */
enum { GB_KIND_NDF_PYRAMID = 1, GB_KIND_TENSOR_NDF = 2 };

/* GB_WRONG_KIND for containers of other asset kinds. */
int32_t gb_ndf_asset_open(const char* path, gb_ndf_asset** out);
int32_t gb_ndf_asset_open_memory(const void* data, size_t size, gb_ndf_asset** out);
void gb_ndf_asset_close(gb_ndf_asset* asset); /* NULL is allowed */

/* Asset kind (GB_KIND_*) and NDF resolution R (bins per side); either pointer may be NULL. */
int32_t gb_ndf_asset_info(const gb_ndf_asset* asset, int32_t* kind, int32_t* resolution);

int32_t gb_ndf_asset_eval(const gb_ndf_asset* asset, double x, double y, double sigma, double sx, double sy,
                          double* value);
int32_t gb_ndf_asset_average(const gb_ndf_asset* asset, double x, double y, double sigma, double sx0, double sy0,
                             double sx1, double sy1, double* value);
int32_t gb_ndf_asset_sample(const gb_ndf_asset* asset, double x, double y, double sigma, double u1, double u2,
                            double* sx, double* sy, double* pdf);
int32_t gb_ndf_asset_pdf(const gb_ndf_asset* asset, double x, double y, double sigma, double sx, double sy,
                         double* pdf);
/* Integral of the footprint's NDF over the s-plane (what sampling normalises by). */
int32_t gb_ndf_asset_mass(const gb_ndf_asset* asset, double x, double y, double sigma, double* mass);
int32_t gb_ndf_asset_image(const gb_ndf_asset* asset, double x, double y, double sigma, float* out, size_t count);

#ifdef __cplusplus
}
#endif

#endif /* GLINTBAKE_C_H */
