# SPDX-License-Identifier: Apache-2.0
# CP tensor decomposition of angular NDF block groups (Deng et al. 2022), factor prefix sums, and the
# tensor-ndf packer that compresses a footprint pyramid group by group.
list(APPEND GLINTBAKE_BAKE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/cp_engine.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cp_init.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cp_decompose.cpp
  ${CMAKE_CURRENT_LIST_DIR}/prefix_sums.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cp_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/synthetic_groups.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tensor_pack_encode.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tensor_pack_sink.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tensor_assembly.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tensor_shard.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tensor_pack.cpp)
