# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# ctest script: install the build tree into a scratch prefix, then configure, build and run two
# consumer projects against it:
# - the library example of docs/library.md: its C++ block (example.cpp) and its CMake block
#   (CMakeLists.txt), between <!-- example:consumer:begin --> and ...:end -->;
# - engine/: the README's engine block linked with MSFusion::pipeline alone, the package found
#   as `msfusion`; its configuration fails when what the engine links holds a ROS library.
# In: BUILD_DIR, README (the document holding the library example), ENGINE_README (the one
# holding the engine example), WORK_DIR, KITTI_DIR; CONSUMER_CXX_FLAGS and CONSUMER_LINK_FLAGS, the
# build's own (make test-sanitize's -fsanitize: the installed libraries need its runtime, and
# the templates both sides instantiate must be compiled alike).
file(REMOVE_RECURSE ${WORK_DIR})
function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(result)
    message(FATAL_ERROR "${step} failed (${result}):\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()
# Configures and builds the project in <source> into <binary> against the installed package.
function(build_consumer name source binary)
  run("configure ${name}" ${CMAKE_COMMAND} -S ${source} -B ${binary} -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}"
      "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINK_FLAGS}" ${ARGN})
  run("build ${name}" ${CMAKE_COMMAND} --build ${binary})
endfunction()

run("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)

include(${CMAKE_CURRENT_LIST_DIR}/../readme_blocks.cmake)
msf_readme_block(${README} consumer cpp source source_line)
msf_readme_block(${README} consumer cmake lists lists_line)
file(WRITE ${WORK_DIR}/src/example.cpp "#line ${source_line} \"${README}\"\n${source}")
file(WRITE ${WORK_DIR}/src/CMakeLists.txt "${lists}")
build_consumer("the library example" ${WORK_DIR}/src ${WORK_DIR}/build)

msf_readme_block(${ENGINE_README} engine cpp source source_line)
file(WRITE ${WORK_DIR}/engine/readme_engine_example.h "#line ${source_line} \"${ENGINE_README}\"\n${source}")
build_consumer("the engine alone" ${CMAKE_CURRENT_LIST_DIR}/engine ${WORK_DIR}/engine/build
               -DEXAMPLE_DIR=${WORK_DIR}/engine)

# A component that is no module fails find_package(... REQUIRED) with the list of modules, in
# either spelling of the package's name.
foreach(package MSFusion msfusion)
  file(WRITE ${WORK_DIR}/bad_${package}/CMakeLists.txt "cmake_minimum_required(VERSION 3.16)\n"
       "project(bad LANGUAGES C CXX)\nfind_package(${package} REQUIRED COMPONENTS fusion nosuch)\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/bad_${package} -B ${WORK_DIR}/bad_${package}/build
                  -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result OR NOT err MATCHES "no module 'nosuch'")
    message(FATAL_ERROR "find_package(${package} COMPONENTS nosuch) was not refused (${result}):\n${err}")
  endif()
endforeach()

set(sequence ${KITTI_DIR}/odometry/sequences/04)
if(NOT EXISTS ${sequence}/velodyne/000000.bin)
  if("$ENV{CI}" STREQUAL "true")
    message(FATAL_ERROR "KITTI sample not found at ${KITTI_DIR}; CI=true requires it")
  endif()
  message(STATUS "KITTI sample not found: the consumers were built but not run")
  return()
endif()
run("run the library example" ${WORK_DIR}/build/app ${sequence}/calib.txt ${sequence}/velodyne/000000.bin
    ${sequence}/image_0/000000.png ${sequence}/image_1/000000.png ${WORK_DIR}/mesh.ply)
# Frame 0 of odometry 04: its scan's points, the image's pixels, and a mesh that is not empty.
if(NOT last_output MATCHES "^124231 points, 453620 pixels, [1-9][0-9][0-9][0-9]+ triangles")
  message(FATAL_ERROR "unexpected output of the example: ${last_output}")
endif()
if(NOT EXISTS ${WORK_DIR}/mesh.ply)
  message(FATAL_ERROR "the example wrote no mesh")
endif()
message(STATUS "consumer output: ${last_output}")

run("run the engine alone" ${WORK_DIR}/engine/build/engine ${sequence} ${WORK_DIR}/engine/mesh.ply)
if(NOT last_output MATCHES "^[1-9][0-9][0-9][0-9]+ triangles")
  message(FATAL_ERROR "unexpected output of the engine alone: ${last_output}")
endif()
message(STATUS "engine output: ${last_output}")
