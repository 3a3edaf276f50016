// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <optional>
#include <string>

namespace msf {

/// Where a rig's frames are in a ROS 1 bag: its topics and tf frames. The defaults are the
/// layout kitti2bag writes for a KITTI drive (and msf_kitti2bag for any dataset). Each image
/// topic's CameraInfo is its sibling `camera_info` (image_transport's convention).
struct BagOptions {
  std::string lidar_topic = "/kitti/velo/pointcloud";            ///< sensor_msgs/PointCloud2
  std::string left_topic = "/kitti/camera_gray_left/image_raw";   ///< sensor_msgs/Image, rectified
  std::string right_topic = "/kitti/camera_gray_right/image_raw"; ///< the stereo pair's other camera
  std::string color_topic = "/kitti/camera_color_left/image_raw"; ///< optional; "" = none
  /// The frame the poses are in (tf from it to the left camera's frame). "" = kitti2bag's
  /// odometry world `camera_init` when the bag has it, else the root of the left camera's tree.
  std::string world_frame;
  /// A scan and an image are one frame when their stamps are at most this far apart.
  double max_offset_s = 0.05;
  /// How the LiDAR takes its scans, which a bag does not say: swept over their period (a
  /// spinning LiDAR's, the default) or at one instant (false). Unset: swept, or a -rig file's.
  std::optional<bool> sweeping_scans;

  /// Whether every field is its default (options for a bag given with another dataset are an error).
  bool isDefault() const {
    const BagOptions d;
    return lidar_topic == d.lidar_topic && left_topic == d.left_topic && right_topic == d.right_topic &&
           color_topic == d.color_topic && world_frame == d.world_frame && max_offset_s == d.max_offset_s &&
           !sweeping_scans;
  }
};

} // namespace msf
