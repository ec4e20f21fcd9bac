# SPDX-License-Identifier: Apache-2.0
# Runtime-lite reader of wang-tiles assets (Wang tiles on an implicit hashed grid).
list(APPEND GLINTBAKE_RUNTIME_SOURCES ${CMAKE_CURRENT_LIST_DIR}/wang_ndf.cpp)
