# Shared build helpers: the warnings target, the one function that defines every library, and the
# package export.
include_guard(GLOBAL)
include(CMakePackageConfigHelpers)

add_library(glintbake_warnings INTERFACE)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  target_compile_options(glintbake_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                                      -Wcast-align -Wunused -Woverloaded-virtual -Wnull-dereference)
  if(GLINTBAKE_WERROR)
    target_compile_options(glintbake_warnings INTERFACE -Werror)
  endif()
elseif(MSVC)
  target_compile_options(glintbake_warnings INTERFACE /W4)
endif()

set_property(GLOBAL PROPERTY GLINTBAKE_EXPORTED_TARGETS "")

# glintbake_add_library(<name> SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...] [INCLUDE_DIR dir]
#                       [NO_EXCEPTIONS] [INTERNAL])
# Defines target glintbake_<name> with alias glintbake::<name>. Public headers live in
# <INCLUDE_DIR> (default: include/ beside the CMakeLists that calls it). INTERNAL libraries are
# not installed (tool scaffolding, test helpers).
function(glintbake_add_library name)
  cmake_parse_arguments(ARG "NO_EXCEPTIONS;INTERNAL" "INCLUDE_DIR" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target glintbake_${name})
  add_library(${target} ${ARG_SOURCES})
  add_library(glintbake::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME glintbake_${name}
                                             POSITION_INDEPENDENT_CODE ON)
  if(NOT ARG_INCLUDE_DIR)
    set(ARG_INCLUDE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/include)
  endif()
  if(EXISTS ${ARG_INCLUDE_DIR})
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${ARG_INCLUDE_DIR}>
                                                $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  endif()
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated/include>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS}
                                         $<BUILD_INTERFACE:glintbake_warnings>)
  target_compile_features(${target} PUBLIC cxx_std_17)
  if(ARG_NO_EXCEPTIONS AND CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -fno-exceptions -fno-rtti)
  endif()
  if(NOT ARG_INTERNAL)
    install(TARGETS ${target} EXPORT glintbakeTargets
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
            RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
    if(EXISTS ${ARG_INCLUDE_DIR})
      install(DIRECTORY ${ARG_INCLUDE_DIR}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    endif()
    set_property(GLOBAL APPEND PROPERTY GLINTBAKE_EXPORTED_TARGETS ${target})
  endif()
endfunction()

# glintbake_add_tool(<name> SOURCES ... [DEPS ...]): one command-line program, installed.
function(glintbake_add_tool name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE glintbake::cli ${ARG_DEPS} glintbake_warnings)
  install(TARGETS ${name} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endfunction()

function(glintbake_install_package)
  if(TARGET glintbake_bake)
    set(GLINTBAKE_CONFIG_WITH_BAKE ON)
  else()
    set(GLINTBAKE_CONFIG_WITH_BAKE OFF)
  endif()
  configure_file(${PROJECT_SOURCE_DIR}/cmake/version.h.in
                 ${PROJECT_BINARY_DIR}/generated/include/glintbake/version.h @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/generated/include/glintbake/version.h
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/glintbake)
  install(EXPORT glintbakeTargets NAMESPACE glintbake:: FILE glintbakeTargets.cmake
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/glintbake)
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/glintbakeConfig.cmake.in
                                ${PROJECT_BINARY_DIR}/glintbakeConfig.cmake
                                INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/glintbake)
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/glintbakeConfigVersion.cmake
                                   COMPATIBILITY SameMajorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/glintbakeConfig.cmake ${PROJECT_BINARY_DIR}/glintbakeConfigVersion.cmake
                ${PROJECT_SOURCE_DIR}/cmake/FindGlintbakeOIIO.cmake
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/glintbake)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/schemas/ DESTINATION ${CMAKE_INSTALL_DATADIR}/glintbake/schemas)
endfunction()
