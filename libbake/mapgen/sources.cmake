# SPDX-License-Identifier: Apache-2.0
# Procedural normal maps with known statistics (mapgen.h).
list(APPEND GLINTBAKE_BAKE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/mapgen.cpp
  ${CMAKE_CURRENT_LIST_DIR}/gaussian_surface.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scratches.cpp
  ${CMAKE_CURRENT_LIST_DIR}/flakes.cpp)
