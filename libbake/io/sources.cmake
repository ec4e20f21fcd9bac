# SPDX-License-Identifier: Apache-2.0
# Normal-map ingest (ingest.cpp, normal_map.cpp) and image output (image_io.cpp).
list(APPEND GLINTBAKE_BAKE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/ingest.cpp
  ${CMAKE_CURRENT_LIST_DIR}/normal_map.cpp
  ${CMAKE_CURRENT_LIST_DIR}/image_io.cpp)
