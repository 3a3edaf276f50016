// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_ros_node: the reconstruction engine as a ROS 1 node (docs/ros.md). Subscribes to a LiDAR's
// PointCloud2 and a rectified stereo pair with its CameraInfo (and a colour camera), the poses
// from tf or the engine's odometry; publishes ~depth and ~weight (32FC1), ~points (PointCloud2)
// and ~mesh (a Marker triangle list), and saves the mesh at shutdown. Parameters:
// config/kitti_bag.yaml, and `msf_ros_node -h`.
#include "reconstruction_node.h"

#include <msf/common/huge_page_images.h>
#include <msf/common/tool.h>

#include <ros/init.h>
#include <ros/master.h>
#include <ros/network.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace ros::master {
// roscpp's own, exported but not in its headers: the master's URI from __master:= or
// ROS_MASTER_URI, as ros::init sets it. ROS 1 is frozen, so the symbol stays.
ROSCPP_DECL void init(const M_string& remappings);
} // namespace ros::master

namespace {
std::atomic<bool> g_stop{false};

/// The master's URI as ros::init takes it (a __master:= argument, else ROS_MASTER_URI) and
/// where it comes from, checked before ros::init: ROS ends a node whose master URI it cannot
/// parse with a breakpoint trap. Empty when the URI parses or none is given.
std::string unparsableMasterUri(int argc, char** argv) {
  const std::string remap = "__master:=";
  std::string uri, from;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]).rfind(remap, 0) == 0) {
      uri = std::string(argv[i]).substr(remap.size());
      from = "the argument " + remap;
    }
  if (from.empty() && std::getenv("ROS_MASTER_URI")) {
    uri = std::getenv("ROS_MASTER_URI");
    from = "ROS_MASTER_URI";
  }
  std::string host;
  std::uint32_t port = 0;
  return from.empty() || ros::network::splitURI(uri, host, port) ? "" : "'" + uri + "' (" + from + ")";
}

/// The first argument that is not a ROS remapping (name:=value), or "".
std::string firstArgumentNotRos(int argc, char** argv) {
  ros::V_string arguments;
  ros::removeROSArgs(argc, argv, arguments);
  return arguments.size() > 1 ? arguments[1] : "";
}

/// The arguments' remappings (name:=value), as ros::init reads them.
ros::M_string remappingsOf(int argc, char** argv) {
  ros::M_string remappings;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (const std::size_t at = argument.find(":="); at != std::string::npos)
      remappings[argument.substr(0, at)] = argument.substr(at + 2);
  }
  return remappings;
}

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
  if (msf::tool::wantsVersion(argc, argv)) {
    std::printf("%s\n", msf::tool::versionLine("msf_ros_node").c_str());
    return 0;
  }
  if (msf::tool::wantsHelp(argc, argv)) {
    std::printf("%s%s\n", msf::NodeParameters::help().c_str(), msf::tool::versionLine("msf_ros_node").c_str());
    return 0;
  }
  const std::string unexpected = firstArgumentNotRos(argc, argv);
  if (!unexpected.empty()) {
    std::fprintf(stderr,
                 "msf_ros_node: error: unexpected argument '%s': the node takes -h, --version, remappings "
                 "(topic:=name) and parameters (_name:=value)\n",
                 unexpected.c_str());
    return 1;
  }
  // SIGINT and SIGTERM stop the node while ROS still runs, so that it finishes the frames
  // waiting (their poses from tf), publishes the last mesh and logs what it dropped.
  const std::string bad_uri = unparsableMasterUri(argc, argv);
  if (!bad_uri.empty()) {
    std::fprintf(stderr, "msf_ros_node: error: the ROS master's URI %s is not of the form http://host:port\n",
                 bad_uri.c_str());
    return 1;
  }
  std::signal(SIGINT, [](int) { g_stop = true; });
  std::signal(SIGTERM, [](int) { g_stop = true; });
  // Waited for before ros::init, which sets the _name:=value parameters on the master and would
  // wait for it in silence, deaf to the stop signals.
  ros::master::init(remappingsOf(argc, argv));
  if (!waitForMaster()) {
    std::fprintf(stderr, "msf_ros_node: stopped while waiting for the ROS master; nothing was done\n");
    return 130;
  }
  ros::init(argc, argv, "msf_ros_node", ros::init_options::NoSigintHandler);
  msf::useHugePagesForLargeImages();
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
