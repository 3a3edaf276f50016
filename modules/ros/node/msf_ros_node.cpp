// msf_ros_node: the reconstruction engine as a ROS 1 node (docs/ros.md). Subscribes to a LiDAR's
// PointCloud2 and a rectified stereo pair with its CameraInfo (and a colour camera), the poses
// from tf; publishes ~depth and ~weight (32FC1), ~points (PointCloud2) and ~mesh (a Marker
// triangle list), and saves the mesh at shutdown. Parameters: config/ros_node.yaml.
#include "reconstruction_node.h"

#include <cstdio>

int main(int argc, char** argv) {
  ros::init(argc, argv, "msf_ros_node");
  ros::NodeHandle nh, private_nh("~");
  try {
    msf::ReconstructionNode node(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "msf_ros_node: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
