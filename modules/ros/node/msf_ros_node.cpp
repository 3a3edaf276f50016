// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_ros_node: the reconstruction engine as a ROS 1 node (docs/ros.md). Subscribes to a LiDAR's
// PointCloud2 and a rectified stereo pair with its CameraInfo (and a colour camera), the poses
// from tf or the engine's odometry; publishes ~depth and ~weight (32FC1), ~points (PointCloud2)
// and ~mesh (a Marker triangle list), and saves the mesh at shutdown. Parameters:
// config/kitti_bag.yaml.
#include "reconstruction_node.h"

#include <ros/master.h>

#include <atomic>
#include <csignal>
#include <cstdio>

namespace {
std::atomic<bool> g_stop{false};

/// Waits for the ROS master, as ROS's nodes do, until a stop signal: ROS's own retries would not
/// see one, since its SIGINT handler is replaced. False when stopped first.
bool waitForMaster() {
  for (bool said = false; !g_stop; ros::WallDuration(0.2).sleep()) {
    if (ros::master::check())
      return true;
    if (!said)
      std::fprintf(stderr, "msf_ros_node: waiting for the ROS master at %s\n", ros::master::getURI().c_str());
    said = true;
  }
  return false;
}
} // namespace

int main(int argc, char** argv) {
  // SIGINT and SIGTERM stop the node while ROS still runs, so that it finishes the frames
  // waiting (their poses from tf), publishes the last mesh and logs what it dropped.
  ros::init(argc, argv, "msf_ros_node", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, [](int) { g_stop = true; });
  std::signal(SIGTERM, [](int) { g_stop = true; });
  if (!waitForMaster()) {
    std::fprintf(stderr, "msf_ros_node: stopped while waiting for the ROS master; nothing was done\n");
    return 130;
  }
  ros::NodeHandle nh, private_nh("~");
  try {
    msf::ReconstructionNode node(nh, private_nh);
    while (!g_stop && ros::ok())
      ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "msf_ros_node: error: %s\n", e.what());
    return 1;
  }
  ros::shutdown();
  return 0;
}
