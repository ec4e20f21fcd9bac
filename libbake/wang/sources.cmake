# SPDX-License-Identifier: Apache-2.0
# Wang tiles: the tile set from an exemplar, the implicit grid's regions and the per-tile NDF assets.
list(APPEND GLINTBAKE_BAKE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/tile_set.cpp ${CMAKE_CURRENT_LIST_DIR}/tile_ndf.cpp)
