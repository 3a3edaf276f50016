// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace msf {

using PoseList = std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>;

/// KITTI odometry poses/XX.txt: one 3x4 row-major T_world_cam0 a line (blank lines and lines
/// starting with # are skipped).
/// Throws IOError naming file and line for a line that is not 12 finite numbers or not a
/// rigid transform (limits::checkRigid: orthonormal rotation, translation within 1000 km).
PoseList loadOdometryPoses(const std::string& path);

/// Writes poses in the odometry format, atomically.
void saveOdometryPoses(const std::string& path, const PoseList& T_world_cam0);

/// One OXTS record (the fields the pose needs) of a KITTI raw drive.
struct OxtsRecord {
  double lat = 0, lon = 0, alt = 0;     ///< degrees, degrees, metres
  double roll = 0, pitch = 0, yaw = 0;  ///< radians
};

/// Reads one OXTS record file (oxts/data/NNNNNNNNNN.txt); throws IOError naming it when its
/// first six values are not finite numbers.
OxtsRecord loadOxtsRecord(const std::string& path);

/// Reads oxts/data/*.txt of a raw drive folder (sorted by name). A Sequence takes each
/// frame's record by the frame's name instead, so that a gap in the records is not filled by
/// the next one.
std::vector<OxtsRecord> loadOxts(const std::string& oxts_data_dir);

/// Converts OXTS records to T_world_cam0 with the KITTI raw devkit's Mercator formulation
/// (scale from the first latitude), the first frame's camera 0 as the world origin, through
/// calibration.T_velo_imu (calib_imu_to_velo) and calibration.T_cam0_velo.
PoseList oxtsToCameraPoses(const std::vector<OxtsRecord>& oxts, const Calibration& calibration);

} // namespace msf
