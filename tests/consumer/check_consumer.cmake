# ctest script: install the build tree into a scratch prefix, then configure, build and run a
# consumer project made of the README's library example: its C++ block (example.cpp) and its
# CMake block (CMakeLists.txt), between <!-- example:consumer:begin --> and ...:end -->.
# In: BUILD_DIR, README, WORK_DIR, KITTI_DIR.
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
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
run("build" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)

set(calib ${KITTI_DIR}/odometry/sequences/04/calib.txt)
set(scan ${KITTI_DIR}/odometry/sequences/04/velodyne/000000.bin)
if(NOT EXISTS ${scan})
  if("$ENV{CI}" STREQUAL "true")
    message(FATAL_ERROR "KITTI sample not found at ${KITTI_DIR}; CI=true requires it")
  endif()
  message(STATUS "KITTI sample not found: the consumer was built but not run")
  return()
endif()
run("run" ${WORK_DIR}/build/app ${calib} ${scan})
if(NOT last_output MATCHES "124231 points")
  message(FATAL_ERROR "unexpected output of the example: ${last_output}")
endif()
message(STATUS "consumer output: ${last_output}")
