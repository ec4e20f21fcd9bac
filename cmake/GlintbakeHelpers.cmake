# SPDX-License-Identifier: Apache-2.0
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
  # In a unity build (CMAKE_UNITY_BUILD) GCC takes each source for a header of the unity file, and
  # warns where one of its classes holds a member whose type is in the source's anonymous namespace.
  if(CMAKE_UNITY_BUILD AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(glintbake_warnings INTERFACE -Wno-subobject-linkage)
  endif()
elseif(MSVC)
  target_compile_options(glintbake_warnings INTERFACE /W4)
endif()

set_property(GLOBAL PROPERTY GLINTBAKE_EXPORTED_TARGETS "")

# glintbake_add_library(<name> SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...] [INCLUDE_DIR dir]
#                       [COMPONENT runtime|bake|render] [NO_EXCEPTIONS] [INTERNAL])
# Defines target glintbake_<name> with alias glintbake::<name>, static or shared as BUILD_SHARED_LIBS
# says. Public headers live in <INCLUDE_DIR> (default: include/ beside the CMakeLists that calls it).
# Installed libraries belong to a package component (find_package(glintbake COMPONENTS ...)), whose
# export set is glintbake-<component>Targets. INTERNAL libraries are static and not installed (tool
# scaffolding, test helpers).
function(glintbake_add_library name)
  cmake_parse_arguments(ARG "NO_EXCEPTIONS;INTERNAL" "INCLUDE_DIR;COMPONENT" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target glintbake_${name})
  if(ARG_INTERNAL)
    add_library(${target} STATIC ${ARG_SOURCES})
  else()
    if(NOT ARG_COMPONENT)
      message(FATAL_ERROR "glintbake_add_library(${name}): installed libraries name their COMPONENT")
    endif()
    add_library(${target} ${ARG_SOURCES})
  endif()
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
    install(TARGETS ${target} EXPORT glintbake-${ARG_COMPONENT}Targets
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
            RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
    if(EXISTS ${ARG_INCLUDE_DIR})
      install(DIRECTORY ${ARG_INCLUDE_DIR}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    endif()
    set_property(GLOBAL APPEND PROPERTY GLINTBAKE_EXPORTED_TARGETS ${target})
    set_property(GLOBAL APPEND PROPERTY GLINTBAKE_INSTALLED_COMPONENTS ${ARG_COMPONENT})
  endif()
endfunction()

# glintbake_add_tool(<name> SOURCES ... [DEPS ...]): one command-line program, installed.
function(glintbake_add_tool name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE glintbake::cli ${ARG_DEPS} glintbake_warnings)
  install(TARGETS ${name} EXPORT glintbake-toolsTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  set_property(GLOBAL APPEND PROPERTY GLINTBAKE_INSTALLED_COMPONENTS tools)
endfunction()

# The package: one export set and dependency list per component (cmake/glintbakeConfig.cmake.in),
# the version header, the pkg-config file of the runtime, and the documents and schemas.
function(glintbake_install_package)
  get_property(components GLOBAL PROPERTY GLINTBAKE_INSTALLED_COMPONENTS)
  list(REMOVE_DUPLICATES components)
  set(GLINTBAKE_CONFIG_COMPONENTS "${components}")
  if(BUILD_SHARED_LIBS)
    set(GLINTBAKE_CONFIG_STATIC OFF)
  else()
    set(GLINTBAKE_CONFIG_STATIC ON)
  endif()
  configure_file(${PROJECT_SOURCE_DIR}/cmake/version.h.in
                 ${PROJECT_BINARY_DIR}/generated/include/glintbake/version.h @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/generated/include/glintbake/version.h
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/glintbake)
  foreach(component ${components})
    install(EXPORT glintbake-${component}Targets NAMESPACE glintbake:: FILE glintbake-${component}Targets.cmake
            DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/glintbake)
  endforeach()
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/glintbakeConfig.cmake.in
                                ${PROJECT_BINARY_DIR}/glintbakeConfig.cmake
                                INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/glintbake)
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/glintbakeConfigVersion.cmake
                                   COMPATIBILITY SameMajorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/glintbakeConfig.cmake ${PROJECT_BINARY_DIR}/glintbakeConfigVersion.cmake
                ${PROJECT_SOURCE_DIR}/cmake/FindGlintbakeOIIO.cmake
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/glintbake)

  # pkg-config: a static runtime needs zstd and the C++ standard library at link time, a shared one
  # only for its own loading.
  if(BUILD_SHARED_LIBS)
    set(GLINTBAKE_PC_REQUIRES "")
    set(GLINTBAKE_PC_REQUIRES_PRIVATE "libzstd")
    set(GLINTBAKE_PC_LIBS_EXTRA "")
  else()
    set(GLINTBAKE_PC_REQUIRES "libzstd")
    set(GLINTBAKE_PC_REQUIRES_PRIVATE "")
    set(GLINTBAKE_PC_LIBS_EXTRA "-lstdc++ -lm")
  endif()
  file(RELATIVE_PATH GLINTBAKE_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/glintbake-runtime.pc.in ${PROJECT_BINARY_DIR}/glintbake-runtime.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/glintbake-runtime.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

  install(DIRECTORY ${PROJECT_SOURCE_DIR}/schemas/ DESTINATION ${CMAKE_INSTALL_DATADIR}/glintbake/schemas)
  install(FILES ${PROJECT_SOURCE_DIR}/formats/SPEC.md ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/LICENSE
                ${PROJECT_SOURCE_DIR}/NOTICE ${PROJECT_SOURCE_DIR}/THIRD_PARTY_NOTICES.md
          DESTINATION ${CMAKE_INSTALL_DOCDIR})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/schemas/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/schemas)
  if(EXISTS ${PROJECT_SOURCE_DIR}/docs)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR})
  endif()
endfunction()
