# SPDX-License-Identifier: Apache-2.0
# The reference renderer (glintbake::render): scenes, camera and objects with ray differentials,
# direct lighting with the glinty BRDF over image tiles, and image comparison. Its own target,
# because it uses both the runtime (assets, BRDF) and the reference evaluator (ground truth).
find_package(nlohmann_json REQUIRED CONFIG)
glintbake_add_library(render
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/scene.cpp
          ${CMAKE_CURRENT_LIST_DIR}/geometry.cpp
          ${CMAKE_CURRENT_LIST_DIR}/reference_ndf.cpp
          ${CMAKE_CURRENT_LIST_DIR}/renderer.cpp
          ${CMAKE_CURRENT_LIST_DIR}/image_compare.cpp
  PUBLIC_DEPS glintbake::bake glintbake::runtime
  COMPONENT render
  # nlohmann-json is a header library used only inside the scene reader.
  PRIVATE_DEPS glintbake::reference TBB::tbb OpenImageIO::OpenImageIO $<BUILD_INTERFACE:nlohmann_json::nlohmann_json>)
