# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# One place for how every target of ours is compiled: the warnings (as errors) and the
# precompiled headers.
option(MSF_WARNINGS_AS_ERRORS "Treat compiler warnings as errors" ON)

# The external headers nearly every source file includes, parsed once per build instead of once
# per file. -DCMAKE_DISABLE_PRECOMPILE_HEADERS=ON builds without them (ccache caches a build with
# them only given CCACHE_SLOPPINESS=pch_defines,time_macros). A file still includes what it uses:
# the build without them (make test-sanitize-fast) checks it.
set(MSF_PRECOMPILED_HEADERS
  <algorithm> <array> <cmath> <cstdint> <filesystem> <fstream> <functional> <map> <memory> <sstream>
  <string> <vector> <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp> <opencv2/imgproc.hpp>
  <pcl/point_cloud.h> <pcl/point_types.h>)

# msf_add_precompiled_headers(<target> LIBS ... HEADERS ...): an object library that compiles
# HEADERS with the flags LIBS bring and our warnings' (-Wpedantic changes the predefined macros),
# for the targets that reuse them. GCC drops a PCH made with a macro the file lacks, so these
# targets have no definitions of an msf_ library's.
function(msf_add_precompiled_headers name)
  cmake_parse_arguments(ARG "" "" "LIBS;HEADERS" ${ARGN})
  if(CMAKE_DISABLE_PRECOMPILE_HEADERS)
    return()
  endif()
  set(source ${PROJECT_BINARY_DIR}/precompiled/${name}.cpp)
  if(NOT EXISTS ${source})
    file(WRITE ${source} "// The precompiled headers of target ${name}, which other targets reuse.\n")
  endif()
  add_library(${name} OBJECT ${source})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS})
  target_precompile_headers(${name} PRIVATE ${ARG_HEADERS})
  msf_set_warnings(${name})
endfunction()

function(msf_set_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor
      -Wno-deprecated-declarations>)
  if(MSF_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-Werror>)
  endif()
endfunction()

# msf_set_source_options(<file>... OPTIONS ...): files compiled with options of their own, and
# without the precompiled headers, whose inline functions would keep the flags they were
# compiled with (a file's floating-point options would not reach them).
function(msf_set_source_options)
  cmake_parse_arguments(ARG "" "" "OPTIONS" ${ARGN})
  set_source_files_properties(${ARG_UNPARSED_ARGUMENTS} PROPERTIES COMPILE_OPTIONS "${ARG_OPTIONS}"
                              SKIP_PRECOMPILE_HEADERS ON)
endfunction()

# msf_check_source_options(): fails the configuration where a file of a target under the project
# has compile options of its own and still reuses the precompiled headers (options set with a bare
# set_source_files_properties rather than msf_set_source_options). Call it once every target exists.
function(msf_check_source_options)
  if(CMAKE_DISABLE_PRECOMPILE_HEADERS)
    return()
  endif()
  set(directories ${PROJECT_SOURCE_DIR})
  while(directories)
    list(POP_FRONT directories directory)
    get_property(subdirectories DIRECTORY ${directory} PROPERTY SUBDIRECTORIES)
    list(APPEND directories ${subdirectories})
    get_property(targets DIRECTORY ${directory} PROPERTY BUILDSYSTEM_TARGETS)
    foreach(target IN LISTS targets)
      get_target_property(sources ${target} SOURCES)
      get_target_property(source_dir ${target} SOURCE_DIR)
      if(NOT sources)
        continue()
      endif()
      foreach(source IN LISTS sources)
        if(source MATCHES "^\\$<")
          continue() # a generator expression: another target's objects
        endif()
        get_filename_component(source ${source} ABSOLUTE BASE_DIR ${source_dir})
        get_source_file_property(options ${source} TARGET_DIRECTORY ${target} COMPILE_OPTIONS)
        get_source_file_property(flags ${source} TARGET_DIRECTORY ${target} COMPILE_FLAGS)
        get_source_file_property(skips ${source} TARGET_DIRECTORY ${target} SKIP_PRECOMPILE_HEADERS)
        if((options OR flags) AND NOT skips)
          message(FATAL_ERROR "${source} (target ${target}) has compile options of its own but reuses the "
                              "precompiled headers, whose inline functions keep theirs: set them with "
                              "msf_set_source_options (cmake/CompilerOptions.cmake)")
        endif()
      endforeach()
    endforeach()
  endwhile()
endfunction()

# Call it after target_link_libraries: whether the target links GoogleTest picks its headers.
function(msf_set_compiler_options target)
  msf_set_warnings(${target})
  if(CMAKE_DISABLE_PRECOMPILE_HEADERS)
    return()
  endif()
  # Targets that link GoogleTest reuse the tests' headers (tests/CMakeLists.txt); the others, the libraries'.
  get_target_property(libs ${target} LINK_LIBRARIES)
  if(libs MATCHES "msf_test_support|GTest::")
    target_precompile_headers(${target} REUSE_FROM msf_test_precompiled)
  else()
    target_precompile_headers(${target} REUSE_FROM msf_precompiled)
  endif()
endfunction()
