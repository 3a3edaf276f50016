// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>

#include <string>

namespace msf {

/// A rig file: the calibration of a user's own sensors in plain YAML, as robotics users write
/// it (KITTI's P matrices and ROS camera_info's conventions are the model). All cameras are
/// rectified onto one image plane; camera 0 (`left`) is the reference frame.
///
///   image_width: 640
///   image_height: 480
///   left: {fx: 500.0, fy: 500.0, cx: 320.0, cy: 240.0}   # or P: [12 numbers, row-major 3x4]
///   baseline_m: 0.12                                       # or right: {P: [...]}, Tx = -fx * B
///   color: {P: [...]}                                      # optional: camera 2, else the left
///   color_right: {P: [...]}                                # optional: camera 3
///   lidar:
///     T_cam_lidar: [16 numbers, row-major 4x4]             # the LiDAR's points into the left camera
///     rings: 32                                            # optional: its beams
///     beam_elevations_deg: [-15.0, ..., 15.0]              # optional: one per ring
///     sweeping: true                                       # optional: a spinning LiDAR (deskewed; skew allowed)
///
/// True when `path` is a YAML map with a rig's key (image_width, left, baseline_m, lidar, ...),
/// or without OpenCV's "%YAML" first line, and not OpenCV's camera file (saveCalibrationYaml,
/// whose keys are P0..P3): a rig file that misses a key or misspells one is then refused naming it.
bool isRigFile(const std::string& path);

/// Reads a rig file. Throws CalibrationError naming the file and the key that is missing,
/// unknown (a misspelling), malformed or cannot be right (a non-positive focal length or baseline, a right camera on
/// the left, a non-rigid extrinsic), IOError when the file is not YAML.
Calibration loadRigFile(const std::string& path);

/// The rig a rig file with only the required keys describes, from its numbers: the left camera
/// (camera 0, which also colours), the right one `baseline_m` to its right, and the LiDAR at
/// `T_cam_lidar` (its points into the left camera; none: cameras only) with `lidar`'s beams.
/// Throws CalibrationError naming what cannot be right, as loadRigFile.
Calibration makeRig(cv::Size image_size, double fx, double fy, double cx, double cy, double baseline_m,
                    const Eigen::Isometry3d* T_cam_lidar, const Calibration::Lidar& lidar = {});

/// Writes `calibration` as a rig file (the right camera's P, the colour camera's when it is
/// not the left one), atomically.
void saveRigFile(const Calibration& calibration, const std::string& path);

} // namespace msf
