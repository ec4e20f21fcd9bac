# SPDX-License-Identifier: Apache-2.0
# Runtime-lite reader of ndf-pyramid assets and its C API.
list(APPEND GLINTBAKE_RUNTIME_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/ndf_pyramid.cpp
  ${CMAKE_CURRENT_LIST_DIR}/open_asset.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ndf_asset.cpp
  ${CMAKE_CURRENT_LIST_DIR}/glintbake_ndf_c.cpp)
