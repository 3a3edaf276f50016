// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/tool.h>
#include <msf/io/bag_options.h>
#include <msf/io/frame_source.h>

#include <memory>
#include <string>
#include <vector>

namespace msf {

/// What a dataset is read with, beyond its path.
struct DatasetOptions {
  /// A calibration or rig file (-calib / -rig): required by layouts that carry none, and
  /// overriding the dataset's own otherwise. "" = the dataset's.
  std::string rig;
  /// A ROS bag's topics and frames (kitti2bag's by default); for bags only.
  BagOptions bag;
};

/// Opens a dataset by what the path holds: a folder of the generic layout (FolderSource:
/// left/, right/, lidar/ and a rig file), a KITTI odometry sequence (or a root with one
/// sequence, as msf_synth writes), a KITTI raw drive, or a ROS 1 bag (a file that starts as one
/// does: msf::BagSource, in builds with the ros module). Throws IOError naming the path and the
/// layouts it knows when it is none of them.
std::unique_ptr<FrameSource> openDataset(const std::string& path, const DatasetOptions& options = {});

/// The options every tool that opens a dataset takes: -rig, and a bag's topics, world frame and
/// stamps' offset (-lidar_topic, -left_topic, -right_topic, -color_topic, -world_frame, -max_offset).
void addDatasetOptions(tool::CommandLine& cli, DatasetOptions& options);

/// Whether `path` is a ROS 1 bag file (its first bytes are "#ROSBAG V").
bool isRosBag(const std::string& path);

} // namespace msf
