# ctest script: install the build tree into a scratch prefix, then configure, build and run a
# consumer project whose source is the library example of README.md.
# In: BUILD_DIR, SOURCE_DIR (this folder), README, WORK_DIR, KITTI_DIR.
file(REMOVE_RECURSE ${WORK_DIR})
function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(result)
    message(FATAL_ERROR "${step} failed (${result}):\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

run("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)

# The README's example, between its markers, is the consumer's source.
file(READ ${README} readme)
string(REGEX MATCH "<!-- example:begin -->[^`]*```cpp\n(.*)```[^`]*<!-- example:end -->" found "${readme}")
if(NOT found)
  message(FATAL_ERROR "README.md has no ```cpp block between <!-- example:begin --> and <!-- example:end -->")
endif()
file(WRITE ${WORK_DIR}/src/example.cpp "${CMAKE_MATCH_1}")
file(COPY ${SOURCE_DIR}/CMakeLists.txt DESTINATION ${WORK_DIR}/src)

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
run("run" ${WORK_DIR}/build/example ${calib} ${scan})
if(NOT last_output MATCHES "124231 points")
  message(FATAL_ERROR "unexpected output of the example: ${last_output}")
endif()
message(STATUS "consumer output: ${last_output}")
