# CP tensor decomposition of angular NDF block groups (Deng et al. 2022) and factor prefix sums.
list(APPEND GLINTBAKE_BAKE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/cp_engine.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cp_init.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cp_decompose.cpp
  ${CMAKE_CURRENT_LIST_DIR}/prefix_sums.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cp_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/synthetic_groups.cpp)
