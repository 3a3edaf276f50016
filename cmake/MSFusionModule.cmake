# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# msf_add_module(<name> [DEPS ...] [PRIVATE_DEPS ...])
# Builds modules/<name>/src/*.cpp into the library msf_<name> (alias MSFusion::<name>),
# exported for find_package(MSFusion). Headers live in modules/<name>/include/msf/<name>/.
# A module without sources yet, or whose msf_ dependencies are not built, is skipped.
function(msf_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  if(NOT sources)
    message(STATUS "module ${name}: no sources yet, skipped")
    return()
  endif()
  foreach(dep ${ARG_DEPS})
    if(dep MATCHES "^msf_" AND NOT TARGET ${dep})
      message(STATUS "module ${name}: skipped until ${dep} exists")
      return()
    endif()
  endforeach()
  set(target msf_${name})
  add_library(${target} ${sources})
  add_library(MSFusion::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:include>)
  target_link_libraries(${target} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_features(${target} PUBLIC cxx_std_17)
  msf_set_compiler_options(${target})
  install(TARGETS ${target} EXPORT MSFusionTargets
    ARCHIVE DESTINATION lib LIBRARY DESTINATION lib RUNTIME DESTINATION bin)
  install(DIRECTORY include/ DESTINATION include)
  set_property(GLOBAL APPEND PROPERTY MSF_MODULE_TARGETS ${target})
endfunction()

# The msf_* libraries a source file uses, read from its `#include <msf/<module>/...>` lines,
# so tools, tests and benchmarks link exactly what they include. `missing` receives the
# modules included but not built (skipped above), so their users can be skipped too.
function(msf_modules_used_by out missing)
  set(result msf_common)
  set(absent "")
  foreach(source ${ARGN})
    file(STRINGS ${source} lines REGEX "^#include [<\"]msf/[a-z_]+/")
    foreach(line ${lines})
      string(REGEX REPLACE "^#include [<\"]msf/([a-z_]+)/.*" "msf_\\1" module ${line})
      if(TARGET ${module})
        list(APPEND result ${module})
      else()
        list(APPEND absent ${module})
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES result)
  if(absent)
    list(REMOVE_DUPLICATES absent)
  endif()
  set(${out} ${result} PARENT_SCOPE)
  set(${missing} ${absent} PARENT_SCOPE)
endfunction()

# msf_add_tool(<name>): tools/<name>.cpp into build/bin/<name>. A tool named like a module's
# library (msf_stereo) gets the target <name>_tool and keeps its file name.
function(msf_add_tool name)
  set(source ${CMAKE_CURRENT_SOURCE_DIR}/${name}.cpp)
  msf_modules_used_by(libs missing ${source})
  if(missing)
    message(STATUS "tool ${name}: skipped until ${missing} exist")
    return()
  endif()
  set(target ${name})
  if(TARGET ${name})
    set(target ${name}_tool)
  endif()
  add_executable(${target} ${source})
  set_target_properties(${target} PROPERTIES OUTPUT_NAME ${name})
  target_link_libraries(${target} PRIVATE ${libs})
  msf_set_compiler_options(${target})
  install(TARGETS ${target} RUNTIME DESTINATION bin)
endfunction()

# msf_add_test(<name> SOURCES ... [LABELS ...])
function(msf_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LABELS" ${ARGN})
  msf_modules_used_by(libs missing ${ARG_SOURCES})
  if(missing)
    message(STATUS "test ${name}: skipped until ${missing} exist")
    return()
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${libs} msf_test_support)
  msf_set_compiler_options(${name})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  gtest_discover_tests(${name}
    WORKING_DIRECTORY ${PROJECT_BINARY_DIR}
    # One variable only: gtest_discover_tests keeps only the first item of a list here. The
    # tests know the source and bin folders from test_support's compile definitions.
    PROPERTIES ENVIRONMENT "MSF_KITTI_DIR=${MSF_KITTI_DIR}"
               LABELS "${ARG_LABELS}"
    DISCOVERY_TIMEOUT 60)
endfunction()
