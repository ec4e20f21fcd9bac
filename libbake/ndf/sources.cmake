# SPDX-License-Identifier: Apache-2.0
# NDF pyramid baking: flake construction, bin-integrated splatting, streamed pyramid generation.
list(APPEND GLINTBAKE_BAKE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/flakes.cpp
  ${CMAKE_CURRENT_LIST_DIR}/splat.cpp
  ${CMAKE_CURRENT_LIST_DIR}/pyramid_builder.cpp
  ${CMAKE_CURRENT_LIST_DIR}/flakes_section.cpp)
