# CP-compressed angular NDF blocks: blended point, range, sample and pdf queries.
list(APPEND GLINTBAKE_RUNTIME_SOURCES ${CMAKE_CURRENT_LIST_DIR}/cp_block.cpp)
