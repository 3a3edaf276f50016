// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/datasets/open_dataset.h>
#include <msf/io/folder_source.h>
#include <msf/io/sequence.h>
#ifdef MSF_WITH_ROS
#include <msf/ros/bag_source.h>
#endif

#include <fstream>

namespace msf {

void addDatasetOptions(tool::CommandLine& cli, DatasetOptions& options) {
  BagOptions& bag = options.bag;
  cli.value("-rig", "FILE", options.rig,
            "a rig file (docs/usage.md, \"Your own rig\") or KITTI calibration: required by a folder of the generic "
            "layout without rig.yaml, and used instead of a dataset's own (a bag's CameraInfo and LiDAR extrinsic too)")
      .value("-lidar_topic", "T", bag.lidar_topic, "a bag's LiDAR scans, PointCloud2 (default {default})")
      .value("-left_topic", "T", bag.left_topic,
             "a bag's left rectified image (default {default}); each image's CameraInfo is its sibling camera_info")
      .value("-right_topic", "T", bag.right_topic, "a bag's right rectified image (default {default})")
      .value("-color_topic", "T", bag.color_topic,
             "a bag's colour image (default {default}, when the bag has it; '' for none)")
      .value("-world_frame", "F", bag.world_frame,
             "a bag's tf frame of the poses (default: camera_init, kitti2bag's, when the bag has it, else the root "
             "of the left camera's tf tree)")
      .value("-max_offset", "S", bag.max_offset_s,
             "a bag's scan and images are one frame when their stamps are at most S seconds apart (default "
             "{default})")
      .value(
          "-sweeping_scans", "B",
          [&bag](const std::string& text) {
            if (text != "true" && text != "false")
              throw InvalidInputError("-sweeping_scans must be true or false, not '" + text + "'");
            bag.sweeping_scans = text == "true";
          },
          "a bag's LiDAR sweeps each scan over its period (true, a spinning LiDAR's: the default) or takes it at "
          "one instant (false); as msf_ros_node's ~sweeping_scans");
}

bool isRosBag(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  char magic[9] = {};
  return file.read(magic, sizeof magic) && std::string(magic, sizeof magic) == "#ROSBAG V";
}

std::unique_ptr<FrameSource> openDataset(const std::string& path, const DatasetOptions& options) {
  if (isRosBag(path)) {
#ifdef MSF_WITH_ROS
    return std::make_unique<BagSource>(path, options.bag, options.rig);
#else
    throw IOError("'" + path + "' is a ROS bag, and this build has no ROS module (install ROS 1 with `make deps` "
                  "and build again; CMake option MSF_BUILD_ROS)");
#endif
  }
  if (!options.bag.isDefault())
    throw InvalidInputError("bag topics and frames are for a ROS bag, and '" + path + "' is not one");
  if (FolderSource::looksLikeOne(path))
    return std::make_unique<FolderSource>(path, options.rig);
  return std::make_unique<Sequence>(path, options.rig);
}

} // namespace msf
