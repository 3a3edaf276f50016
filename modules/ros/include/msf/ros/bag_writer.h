// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/frame_source.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace msf {

/// How writeKittiBag writes.
struct KittiBagOptions {
  /// Stamp of the first frame, seconds since the epoch; frame i is stamped this plus its
  /// timestamp, to the nanosecond. Fixed (kitti2bag takes the time of conversion), so a
  /// dataset gives the same bag each time.
  double start_time_s = 1.0e9;
  /// "none" (kitti2bag's), "lz4" or "bz2".
  std::string compression = "none";
  /// The camera images: "raw" (kitti2bag's Image on image_raw), or CompressedImage on
  /// image_raw/compressed, "png" (lossless) or "jpeg", as a rig that records compressed does.
  std::string images = "raw";
  /// Replace a file at the bag's path (otherwise it is refused).
  bool overwrite = false;
  /// After each frame written: (frames written, frames in all).
  std::function<void(std::size_t, std::size_t)> progress;
};

/// Throws InvalidInputError naming the option when `options` asks for an unknown compression or
/// image codec, or a start time out of (0, 4e9) s; writeKittiBag checks them first too.
void requireKittiBagOptions(const KittiBagOptions& options);

/// Writes frames of a dataset (a KITTI odometry sequence, a raw drive, a synthetic sequence)
/// into a ROS 1 bag in kitti2bag's layout, what BagSource reads by default:
///  - /kitti/velo/pointcloud: the scan, PointCloud2 of float32 x y z intensity (ring and time
///    too when the frame has them), frame velo_link;
///  - /kitti/camera_gray_left/image_raw (mono8; image_raw/compressed for options.images png or
///    jpeg) and camera_info, camera_gray_right likewise,
///    and camera_color_left (bgr8) when the dataset has colour; CameraInfo's P is the
///    calibration's P0, P1, P2 (the colour pair's right camera is not written: the stages do
///    not use it);
///  - /tf_static at every frame (latched): camera_gray_left -> velo_link (T_cam0_velo),
///    camera_gray_left -> the other cameras at their optical centres, world -> camera_init
///    (the inverse of T_cam0_velo), as kitti2bag writes them;
///  - /tf, when the dataset has poses: camera_init -> camera_gray_left, T_world_cam0.
/// All messages of frame i carry one stamp. Written through a temporary file and a rename;
/// an existing `path` is refused (IOError) unless options.overwrite, as is a source without a
/// LiDAR extrinsic, and options requireKittiBagOptions refuses, before anything is written.
void writeKittiBag(const FrameSource& source, const std::vector<std::size_t>& frames, const std::string& path,
                   const KittiBagOptions& options = {});

} // namespace msf
