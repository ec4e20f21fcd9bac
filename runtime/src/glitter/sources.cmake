# SPDX-License-Identifier: Apache-2.0
# Runtime-lite reader of glitter assets (procedural discrete microfacets).
list(APPEND GLINTBAKE_RUNTIME_SOURCES ${CMAKE_CURRENT_LIST_DIR}/glitter_ndf.cpp)
