# SPDX-License-Identifier: Apache-2.0
# Finds OpenImageIO and repairs a packaging defect of some distributions: the imported target
# lists /usr/include/opencv4 among its include directories even when OpenCV's headers are not
# installed (OIIO's core library does not need them), which makes CMake refuse to generate.
include_guard(GLOBAL)
find_package(OpenImageIO REQUIRED CONFIG)
# Global, so that find_package(OpenImageIO) in any subdirectory reuses this repaired target.
set_target_properties(OpenImageIO::OpenImageIO PROPERTIES IMPORTED_GLOBAL TRUE)
foreach(prop INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
  get_target_property(_dirs OpenImageIO::OpenImageIO ${prop})
  if(_dirs)
    set(_kept "")
    foreach(dir ${_dirs})
      if(EXISTS "${dir}" OR dir MATCHES "^\\$<")
        list(APPEND _kept "${dir}")
      endif()
    endforeach()
    set_target_properties(OpenImageIO::OpenImageIO PROPERTIES ${prop} "${_kept}")
  endif()
endforeach()
