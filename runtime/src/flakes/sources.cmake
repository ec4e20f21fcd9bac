# SPDX-License-Identifier: Apache-2.0
# Exact small-footprint evaluation from the flakes of a normal map, the clustered lobes above it, and
# the hand-overs to a pyramid.
list(APPEND GLINTBAKE_RUNTIME_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/flake_ndf.cpp
  ${CMAKE_CURRENT_LIST_DIR}/lobe_ndf.cpp
  ${CMAKE_CURRENT_LIST_DIR}/handover.cpp)
