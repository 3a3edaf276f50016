# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Finds Debian's ROS 1 (Noetic-era) C++ libraries without catkin: the bag API (rosbag), roscpp,
# tf2 (tf2_ros), message_filters, cv_bridge, pcl_conversions and the message headers the ros
# module uses, and the roscore and rosbag commands its tests start.
#
# Not through the packages' own CMake configs, which run Python modules (catkin_pkg,
# ament_package) of whichever python3 is first on PATH, nor through pkg-config alone: Debian's
# rosbag.pc requires a pluginlib.pc that its (ROS 2) pluginlib does not ship.
#
# Sets ROS1_FOUND, ROS1_INCLUDE_DIRS, ROS1_LIBRARIES (absolute paths, so the exported library
# links where it is installed without this module), ROS1_MISSING (what was not found, in
# words), ROS1_ROSCORE and ROS1_ROSBAG (the commands), and the target ROS1::ROS1.
find_package(PkgConfig QUIET)
set(ROS1_MISSING "")
set(ROS1_INCLUDE_DIRS "")
set(ROS1_LIBRARIES "")

if(PKG_CONFIG_FOUND)
  pkg_check_modules(ROS1_PC QUIET roscpp tf2_ros tf2 message_filters cv_bridge roscpp_serialization rostime)
endif()
if(ROS1_PC_FOUND)
  list(APPEND ROS1_INCLUDE_DIRS ${ROS1_PC_INCLUDE_DIRS})
  list(APPEND ROS1_LIBRARIES ${ROS1_PC_LINK_LIBRARIES})
else()
  list(APPEND ROS1_MISSING "roscpp/tf2_ros/message_filters/cv_bridge (pkg-config)")
endif()

# rosbag and what its header pulls in: pluginlib's class loader and its ROS 2 helpers.
foreach(lib rosbag rosbag_storage class_loader console_bridge)
  find_library(ROS1_${lib}_LIBRARY ${lib})
  if(ROS1_${lib}_LIBRARY)
    list(APPEND ROS1_LIBRARIES ${ROS1_${lib}_LIBRARY})
  else()
    list(APPEND ROS1_MISSING "lib${lib}")
  endif()
endforeach()
set(ROS1_HEADERS
  "rosbag/bag.h|" "pluginlib/class_loader.hpp|pluginlib" "class_loader/class_loader.hpp|class_loader"
  "rcpputils/shared_library.hpp|rcpputils" "rcutils/types.h|rcutils"
  "ament_index_cpp/get_package_prefix.hpp|ament_index_cpp" "sensor_msgs/PointCloud2.h|"
  "visualization_msgs/Marker.h|" "tf2_msgs/TFMessage.h|" "pcl_conversions/pcl_conversions.h|")
foreach(entry ${ROS1_HEADERS})
  string(REPLACE "|" ";" entry "${entry}")
  list(GET entry 0 header)
  list(LENGTH entry n)
  set(suffix "")
  if(n GREATER 1)
    list(GET entry 1 suffix)
  endif()
  string(MAKE_C_IDENTIFIER "${header}" key)
  find_path(ROS1_${key}_DIR ${header} PATH_SUFFIXES ${suffix})
  if(ROS1_${key}_DIR)
    list(APPEND ROS1_INCLUDE_DIRS ${ROS1_${key}_DIR})
  else()
    list(APPEND ROS1_MISSING "${header}")
  endif()
endforeach()

find_program(ROS1_ROSCORE roscore)
find_program(ROS1_ROSBAG rosbag)
foreach(program ROSCORE ROSBAG)
  if(NOT ROS1_${program})
    string(TOLOWER ${program} name)
    list(APPEND ROS1_MISSING "the ${name} command")
  endif()
endforeach()

list(REMOVE_DUPLICATES ROS1_INCLUDE_DIRS)
if(ROS1_MISSING)
  set(ROS1_FOUND FALSE)
  string(REPLACE ";" ", " ROS1_MISSING "${ROS1_MISSING}")
else()
  set(ROS1_FOUND TRUE)
  if(NOT TARGET ROS1::ROS1)
    add_library(ROS1::ROS1 INTERFACE IMPORTED GLOBAL)
    set_target_properties(ROS1::ROS1 PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${ROS1_INCLUDE_DIRS}"
                                                INTERFACE_LINK_LIBRARIES "${ROS1_LIBRARIES}")
  endif()
endif()
