# SPDX-License-Identifier: Apache-2.0
# Runtime-lite LTC area lights: table lookup, polygon integration and their C API.
list(APPEND GLINTBAKE_RUNTIME_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/ltc_table.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ltc_polygon.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ltc_c.cpp)
