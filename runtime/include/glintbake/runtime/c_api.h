// SPDX-License-Identifier: Apache-2.0
/* Linkage of the runtime's C API (glintbake_ndf_c.h, glintbake_brdf_c.h, ltc_c.h). Every C function
 * is declared GLINTBAKE_C_API: exported from a shared runtime (default visibility on ELF and
 * Mach-O, dllexport/dllimport on Windows when GLINTBAKE_RUNTIME_SHARED is defined, which the CMake
 * package and the pkg-config file do for a shared build), plain in a static one. */
#ifndef GLINTBAKE_C_API_H
#define GLINTBAKE_C_API_H

#if defined(_WIN32) && defined(GLINTBAKE_RUNTIME_SHARED)
#if defined(GLINTBAKE_RUNTIME_BUILDING)
#define GLINTBAKE_C_API __declspec(dllexport)
#else
#define GLINTBAKE_C_API __declspec(dllimport)
#endif
#elif defined(__GNUC__) || defined(__clang__)
#define GLINTBAKE_C_API __attribute__((visibility("default")))
#else
#define GLINTBAKE_C_API
#endif

#endif /* GLINTBAKE_C_API_H */
