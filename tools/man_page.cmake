# SPDX-License-Identifier: Apache-2.0
# cmake -P script: writes the man page a tool prints with --help-man (TOOL, OUTPUT).
set(ENV{ASAN_OPTIONS} "detect_leaks=0")  # sanitizer builds: printing a page is no leak check
get_filename_component(_dir ${OUTPUT} DIRECTORY)
file(MAKE_DIRECTORY ${_dir})
execute_process(COMMAND ${TOOL} --help-man OUTPUT_FILE ${OUTPUT}.tmp RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  file(REMOVE ${OUTPUT}.tmp)
  message(FATAL_ERROR "${TOOL} --help-man failed (${rc})")
endif()
file(RENAME ${OUTPUT}.tmp ${OUTPUT})
