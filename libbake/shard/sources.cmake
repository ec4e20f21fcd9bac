# SPDX-License-Identifier: Apache-2.0
# Sharded bakes: shard specs, cost-balanced unit assignment, partial containers.
list(APPEND GLINTBAKE_BAKE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/shard.cpp)
