# SPDX-License-Identifier: Apache-2.0
# The reference evaluator (glintbake::reference): the slow, obviously-correct P-NDF every fast path
# is checked against. Shares no code with libbake/ndf or runtime/.
glintbake_add_library(reference
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/flakes.cpp
          ${CMAKE_CURRENT_LIST_DIR}/pndf.cpp
          ${CMAKE_CURRENT_LIST_DIR}/bin_image.cpp
          ${CMAKE_CURRENT_LIST_DIR}/sampling.cpp
          ${CMAKE_CURRENT_LIST_DIR}/glitter.cpp
  PUBLIC_DEPS glintbake::bake
  COMPONENT bake
  PRIVATE_DEPS TBB::tbb)
