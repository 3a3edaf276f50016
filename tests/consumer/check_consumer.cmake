# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# ctest script: install the build tree into a scratch prefix, then configure, build and run a
# consumer project made of the library example of docs/library.md: its C++ block (example.cpp)
# and its CMake block (CMakeLists.txt), between <!-- example:consumer:begin --> and ...:end -->.
# In: BUILD_DIR, README (the document holding the example), WORK_DIR, KITTI_DIR; CONSUMER_CXX_FLAGS and CONSUMER_LINK_FLAGS, the
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

run("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)

include(${CMAKE_CURRENT_LIST_DIR}/../readme_blocks.cmake)
msf_readme_block(${README} consumer cpp source source_line)
msf_readme_block(${README} consumer cmake lists lists_line)
file(WRITE ${WORK_DIR}/src/example.cpp "#line ${source_line} \"${README}\"\n${source}")
file(WRITE ${WORK_DIR}/src/CMakeLists.txt "${lists}")

run("configure" ${CMAKE_COMMAND} -S ${WORK_DIR}/src -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINK_FLAGS}")
run("build" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)

set(sequence ${KITTI_DIR}/odometry/sequences/04)
if(NOT EXISTS ${sequence}/velodyne/000000.bin)
  if("$ENV{CI}" STREQUAL "true")
    message(FATAL_ERROR "KITTI sample not found at ${KITTI_DIR}; CI=true requires it")
  endif()
  message(STATUS "KITTI sample not found: the consumer was built but not run")
  return()
endif()
run("run" ${WORK_DIR}/build/app ${sequence}/calib.txt ${sequence}/velodyne/000000.bin
    ${sequence}/image_0/000000.png ${sequence}/image_1/000000.png ${WORK_DIR}/mesh.ply)
# Frame 0 of odometry 04: its scan's points, the image's pixels, and a mesh that is not empty.
if(NOT last_output MATCHES "^124231 points, 453620 pixels, [1-9][0-9][0-9][0-9]+ triangles")
  message(FATAL_ERROR "unexpected output of the example: ${last_output}")
endif()
if(NOT EXISTS ${WORK_DIR}/mesh.ply)
  message(FATAL_ERROR "the example wrote no mesh")
endif()
message(STATUS "consumer output: ${last_output}")

# A component that is no module fails find_package(... REQUIRED) with the list of modules.
file(WRITE ${WORK_DIR}/bad/CMakeLists.txt "cmake_minimum_required(VERSION 3.16)\nproject(bad LANGUAGES C CXX)\n"
     "find_package(MSFusion REQUIRED COMPONENTS fusion nosuch)\n")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/bad -B ${WORK_DIR}/bad/build
                -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result OR NOT err MATCHES "no module 'nosuch'")
  message(FATAL_ERROR "COMPONENTS nosuch was not refused as it should be (${result}):\n${err}")
endif()
