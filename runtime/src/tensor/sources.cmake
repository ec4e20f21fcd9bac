# SPDX-License-Identifier: Apache-2.0
# CP-compressed angular NDF blocks: blended point, range, sample and pdf queries, and the reader of
# tensor-ndf assets built on them.
list(APPEND GLINTBAKE_RUNTIME_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/cp_block.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tensor_ndf_load.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tensor_ndf.cpp)
