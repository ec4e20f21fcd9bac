// SPDX-License-Identifier: Apache-2.0
/* Deprecated name of the NDF C API, kept for one minor version: include glintbake_ndf_c.h. The
 * gb_ndf_pyramid_* functions are gone; gb_ndf_asset_* open every NDF asset kind. */
#ifndef GLINTBAKE_C_H
#define GLINTBAKE_C_H

#include <glintbake/runtime/glintbake_ndf_c.h>

#endif /* GLINTBAKE_C_H */
