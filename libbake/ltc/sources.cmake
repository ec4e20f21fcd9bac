# SPDX-License-Identifier: Apache-2.0
# LTC tables (Heitz et al. 2016), multi-scale roughness (Tao et al. 2021) and roughness mips.
find_package(Ceres REQUIRED CONFIG)
find_package(OpenEXR REQUIRED CONFIG)
list(APPEND GLINTBAKE_BAKE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/ltc.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cell_fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fit_table.cpp
  ${CMAKE_CURRENT_LIST_DIR}/published_layout.cpp
  ${CMAKE_CURRENT_LIST_DIR}/table_io.cpp
  ${CMAKE_CURRENT_LIST_DIR}/exr_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/multiscale.cpp
  ${CMAKE_CURRENT_LIST_DIR}/roughness.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sections.cpp)
list(APPEND GLINTBAKE_BAKE_DEPS Ceres::ceres OpenEXR::OpenEXR)
