# SPDX-License-Identifier: Apache-2.0
# cmake -P script of the install tests, one step per call (MODE):
#   install   cmake --install the build tree into PREFIX (the fixture the consumers share)
#   cmake     configure and build the consumer project SOURCE_DIR against PREFIX, then run its
#             program (if it builds one) with WORK_DIR/ARG
#   python    import the installed Python package (PREFIX/PYTHON_DIR) and open ARGS with it
#   pkgconfig compile the C program C_SOURCE with `cc $(pkg-config --cflags --libs glintbake-runtime)`
#             from PREFIX and run it with ARGS
function(run_step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

if(MODE STREQUAL "install")
  file(REMOVE_RECURSE ${PREFIX})
  run_step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX})
elseif(MODE STREQUAL "cmake")
  file(REMOVE_RECURSE ${WORK_DIR})
  run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} -G ${GENERATOR} -DCMAKE_PREFIX_PATH=${PREFIX}
           -DCMAKE_BUILD_TYPE=Release "-DGLINTBAKE_TOOL_NAMES=${TOOL_NAMES}")
  run_step(${CMAKE_COMMAND} --build ${WORK_DIR})
  if(EXISTS ${WORK_DIR}/consumer)
    run_step(${WORK_DIR}/consumer ${WORK_DIR}/${ARG})
  endif()
elseif(MODE STREQUAL "pkgconfig")
  file(REMOVE_RECURSE ${WORK_DIR})
  file(MAKE_DIRECTORY ${WORK_DIR})
  set(ENV{PKG_CONFIG_PATH} "")
  file(GLOB_RECURSE pc_files ${PREFIX}/*/glintbake-runtime.pc)
  list(GET pc_files 0 pc_file)
  get_filename_component(pc_dir ${pc_file} DIRECTORY)
  set(ENV{PKG_CONFIG_PATH} ${pc_dir})
  execute_process(COMMAND ${PKG_CONFIG} --cflags --libs glintbake-runtime RESULT_VARIABLE rc OUTPUT_VARIABLE flags
                  ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pkg-config glintbake-runtime failed: ${err}")
  endif()
  message(STATUS "pkg-config --cflags --libs glintbake-runtime: ${flags}")
  separate_arguments(flags UNIX_COMMAND "${flags}")
  # A shared runtime outside the system's library path is found at run time through an rpath to
  # the prefix's libdir, as a consumer of such a prefix would link it.
  execute_process(COMMAND ${PKG_CONFIG} --variable=libdir glintbake-runtime OUTPUT_VARIABLE libdir
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  # -lm for the program's own math.
  run_step(${C_COMPILER} -std=c99 -Wall -Wextra -Werror ${C_SOURCE} -o ${WORK_DIR}/program ${flags} -lm
           -Wl,-rpath,${libdir})
  run_step(${WORK_DIR}/program ${ARGS})
elseif(MODE STREQUAL "python")
  set(ENV{PYTHONPATH} ${PREFIX}/${PYTHON_DIR})
  run_step(${PYTHON} -c "import glintbake, sys; a = glintbake.open(sys.argv[1]); print('python from install:', glintbake.__file__, a.kind, a.map_size); assert a.kind == 'ndf-pyramid'" ${ARGS})
else()
  message(FATAL_ERROR "unknown MODE '${MODE}'")
endif()
