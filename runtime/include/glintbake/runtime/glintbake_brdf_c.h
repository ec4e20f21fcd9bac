// SPDX-License-Identifier: Apache-2.0
/* C API of the glintbake microfacet BRDF and spherical Gaussian environment prefiltering
 * (brdf.h, sg.h), for engines that do not link C++ directly.
 *
 * Directions are unit vectors {x, y, z} in the tangent frame (x right, y up, z the macro normal),
 * both pointing away from the surface; wi towards the light, wo towards the viewer. BRDF values are
 * per RGB channel in 1/sr. Every function returns a status code (GB_OK = 0 and the other codes of
 * glintbake_ndf_c.h) and writes results through out-parameters. Query functions never allocate and
 * may be called concurrently; gb_brdf_ndf_open/close must not race with queries on that asset.
 * Opening is safe on untrusted files. */
#ifndef GLINTBAKE_BRDF_C_H
#define GLINTBAKE_BRDF_C_H

#include <stdint.h>

#include <glintbake/runtime/c_api.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The P-NDF a BRDF uses as D: any NDF asset kind the runtime reads (ndf-pyramid, tensor-ndf),
 * opened by its container kind. A handle of its own, so that this header stands alone. */
typedef struct gb_brdf_ndf gb_brdf_ndf;
GLINTBAKE_C_API int32_t gb_brdf_ndf_open(const char* path, gb_brdf_ndf** out);
GLINTBAKE_C_API void gb_brdf_ndf_close(gb_brdf_ndf* ndf); /* NULL is allowed */

enum { GB_MODEL_GGX = 0, GB_MODEL_BECKMANN = 1 };
enum { GB_FRESNEL_NONE = 0, GB_FRESNEL_SCHLICK = 1, GB_FRESNEL_CONDUCTOR = 2 };

/* One shading point's BRDF. ndf == NULL selects the analytic (smooth) D of `model` and `alpha`;
 * otherwise D is the asset's P-NDF of the footprint (x, y, sigma in texels) and `model`/`alpha`
 * only give the Smith shadowing. */
typedef struct gb_brdf_params {
  const gb_brdf_ndf* ndf;
  double x, y, sigma;
  int32_t model;   /* GB_MODEL_* */
  double alpha;    /* base roughness, [1e-4, 4] */
  int32_t fresnel; /* GB_FRESNEL_* */
  double f0[3];    /* Schlick reflectance at normal incidence */
  double eta[3];   /* conductor IOR, real part */
  double k[3];     /* conductor IOR, imaginary part */
} gb_brdf_params;

GLINTBAKE_C_API int32_t gb_brdf_eval(const gb_brdf_params* params, const double wi[3], const double wo[3], double f[3]);
/* Samples wi (via the NDF) from two uniforms in [0, 1). *pdf = 0 marks a discarded sample;
 * weight = f cos(theta_i) / pdf. */
GLINTBAKE_C_API int32_t gb_brdf_sample(const gb_brdf_params* params, const double wo[3], double u1, double u2, double wi[3],
                       double* pdf, double weight[3]);
GLINTBAKE_C_API int32_t gb_brdf_pdf(const gb_brdf_params* params, const double wi[3], const double wo[3], double* pdf);

/* A spherical Gaussian light a exp(lambda (mu . v - 1)), mu unit, lambda > 0, a per channel. */
typedef struct gb_sg {
  double axis[3];
  double sharpness;
  double amplitude[3];
} gb_sg;

/* cos(theta_max) of the cone where G >= eps (-1: whole sphere); *empty = 1 when eps > max(a). */
GLINTBAKE_C_API int32_t gb_sg_support(const gb_sg* sg, double eps, double* cos_theta_max, int32_t* empty);
/* Integral of G over the sphere per channel. */
GLINTBAKE_C_API int32_t gb_sg_integral(const gb_sg* sg, double integral[3]);
/* The prefiltered radiance towards wo of the SG light reflected by the BRDF (sg.h). */
GLINTBAKE_C_API int32_t gb_sg_prefiltered_shading(const gb_brdf_params* params, const gb_sg* sg, double eps, const double wo[3],
                                  double radiance[3]);

#ifdef __cplusplus
}
#endif

#endif /* GLINTBAKE_BRDF_C_H */
