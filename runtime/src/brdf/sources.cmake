# SPDX-License-Identifier: Apache-2.0
# Microfacet BRDF with a P-NDF as D, spherical Gaussian environment prefiltering, and their C API.
list(APPEND GLINTBAKE_RUNTIME_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/microfacet_brdf.cpp
  ${CMAKE_CURRENT_LIST_DIR}/layered_brdf.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sg.cpp
  ${CMAKE_CURRENT_LIST_DIR}/glintbake_brdf_c.cpp)
