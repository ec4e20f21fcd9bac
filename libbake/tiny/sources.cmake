# SPDX-License-Identifier: Apache-2.0
# Tiny examples (Xing et al.): the multi-scale tile NDFs of a small example and its asset. The tile
# images come from the runtime's lobe integration, so the baker links the runtime.
list(APPEND GLINTBAKE_BAKE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/tiny_example.cpp)
list(APPEND GLINTBAKE_BAKE_DEPS glintbake::runtime)
