# SPDX-License-Identifier: Apache-2.0
# Procedural glitter: the triangle-integral table, the glitter asset and the pyramid image source.
list(APPEND GLINTBAKE_BAKE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/glitter.cpp)
