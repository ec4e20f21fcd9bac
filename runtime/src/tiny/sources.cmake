# SPDX-License-Identifier: Apache-2.0
# Runtime-lite reader of tiny-example assets (one small example placed over the plane).
list(APPEND GLINTBAKE_RUNTIME_SOURCES ${CMAKE_CURRENT_LIST_DIR}/tiny_example_ndf.cpp)
