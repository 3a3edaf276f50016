# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# msf_check_source_options (cmake/CompilerOptions.cmake) refuses a file whose own compile options
# were set with a bare set_source_files_properties, so that it would reuse the precompiled headers,
# and accepts the same file given them by msf_set_source_options. Each is a small project
# configured in WORK_DIR.
# Usage: cmake -DCMAKE_DIR=<the project's cmake/> -DWORK_DIR=<scratch> -P check_source_options.cmake
foreach(var CMAKE_DIR WORK_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "check_source_options: -D${var}=... is required")
  endif()
endforeach()

file(REMOVE_RECURSE ${WORK_DIR})
file(WRITE ${WORK_DIR}/project/own_options.cpp "int ownOptions() { return 1; }\n")
file(WRITE ${WORK_DIR}/project/plain.cpp "int plain() { return 2; }\n")
file(WRITE ${WORK_DIR}/project/CMakeLists.txt [=[
cmake_minimum_required(VERSION 3.16)
project(source_options_check LANGUAGES CXX)
list(APPEND CMAKE_MODULE_PATH ${MSF_CMAKE_DIR})
include(CompilerOptions)
add_subdirectory(library)
msf_check_source_options()
]=])
# In a subdirectory, as the modules are: the properties live in the target's directory.
file(WRITE ${WORK_DIR}/project/library/CMakeLists.txt [=[
add_library(checked OBJECT ../own_options.cpp ../plain.cpp)
if(HOW STREQUAL "bare")
  set_source_files_properties(../own_options.cpp PROPERTIES COMPILE_OPTIONS -fno-trapping-math)
else()
  msf_set_source_options(../own_options.cpp OPTIONS -fno-trapping-math)
endif()
]=])

function(configure how result_var output_var)
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/project -B ${WORK_DIR}/${how} -DHOW=${how}
                          -DMSF_CMAKE_DIR=${CMAKE_DIR}
                  RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
  set(${result_var} ${result} PARENT_SCOPE)
  set(${output_var} "${output}" PARENT_SCOPE)
endfunction()

configure(helper result output)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "options set by msf_set_source_options were refused:\n${output}")
endif()

configure(bare result output)
string(REGEX REPLACE "[ \n]+" " " output_line "${output}") # CMake wraps its error messages
if(result EQUAL 0)
  message(FATAL_ERROR "options set by a bare set_source_files_properties were accepted:\n${output}")
endif()
set(refusal "own_options\\.cpp \\(target checked\\) has compile options of its own but reuses the precompiled")
if(NOT output_line MATCHES "${refusal} headers")
  message(FATAL_ERROR "the refusal does not name the file, its target and why:\n${output}")
endif()
if(output_line MATCHES "plain\\.cpp")
  message(FATAL_ERROR "the file without options of its own was named:\n${output}")
endif()
message(STATUS "check_source_options: the helper's options accepted, a bare property refused")
