// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include <array>
#include <string>
#include <vector>

namespace msf {

/// The camera model that travels beside the clouds: four rectified cameras (KITTI 0, 1 grey
/// left/right; 2, 3 colour left/right) sharing one rectified image plane, and the LiDAR.
/// All projection matrices map points in the rectified frame of camera 0 to pixels, so a
/// point in camera 0 projects into camera i as P[i] * [x y z 1]^T.
struct Calibration {
  using Projection = Eigen::Matrix<double, 3, 4>;

  std::array<Projection, 4> P;              ///< P_rect_0X (raw) or PX (odometry, object)
  cv::Size image_size{0, 0};                ///< rectified image size; 0x0 when unknown
  Eigen::Isometry3d T_cam0_velo = Eigen::Isometry3d::Identity(); ///< velodyne -> rectified cam 0
  Eigen::Isometry3d T_velo_imu = Eigen::Isometry3d::Identity();  ///< IMU -> velodyne (raw only)
  bool has_imu = false;                     ///< true when T_velo_imu was read
  /// false for a camera-only file (the KITTI stereo benchmarks' P0..P3, no Tr): T_cam0_velo
  /// is then the identity and means nothing
  bool has_velodyne = true;
  std::string source;                       ///< where it was read from, for messages
  /// What the rig says of its LiDAR beyond the extrinsic (a rig file's `lidar:`); KITTI's
  /// calibrations leave it unknown, and the stages take the rings from the scan's order.
  struct Lidar {
    int rings = 0;                          ///< beams, 0 = unknown
    std::vector<double> beam_elevations_deg; ///< one per ring, lowest first; empty = unknown
    bool sweeping = true;                   ///< a spinning LiDAR: each scan swept over its period
  } lidar;

  /// Throws InvalidInputError ("camera index N is not 0..3") unless `camera` is 0..3.
  static void checkCamera(int camera) {
    if (camera < 0 || camera > 3)
      throwNoSuchCamera(camera);
  }
  /// The projection matrix of camera 0..3; throws as checkCamera.
  const Projection& projection(int camera) const {
    checkCamera(camera);
    return P[static_cast<std::size_t>(camera)];
  }
  double fx(int camera = 0) const { return projection(camera)(0, 0); }
  double fy(int camera = 0) const { return projection(camera)(1, 1); }
  double cx(int camera = 0) const { return projection(camera)(0, 2); }
  double cy(int camera = 0) const { return projection(camera)(1, 2); }
  /// Intrinsic matrix of a rectified camera.
  Eigen::Matrix3d K(int camera = 0) const { return projection(camera).leftCols<3>(); }
  /// Optical centre of a camera in the rectified frame of camera 0.
  Eigen::Vector3d cameraCenter(int camera) const;
  /// Distance between two optical centres in metres.
  double baseline(int camera_a, int camera_b) const;
  double baselineGrey() const { return baseline(0, 1); }
  double baselineColor() const { return baseline(2, 3); }
  /// f * B of the grey pair, so that depth = focalBaseline() / disparity; what every stereo
  /// stage asks first. Throws CalibrationError naming `source` when the grey pair cannot be a
  /// rectified stereo pair: f B not > 0 and finite (fx 0, NaN, cameras 0 and 1 at one centre:
  /// a disparity made of it would be silently zero), camera 1 left of camera 0 (swapped images
  /// or sign: the disparities would be of the wrong sign), a baseline outside
  /// limits::kMinBaselineM .. kMaxBaselineM (a unit slip), or checkRectifiedPair(0, 1).
  double focalBaseline() const;
  /// Throws CalibrationError naming `source` and the value unless cameras a and b share their
  /// intrinsics (fx, fy, cx, cy within limits::kRectifiedIntrinsicsTolerancePx) and differ
  /// along x only, as the cameras of a rectified pair do.
  void checkRectifiedPair(int a, int b) const;
  /// Throws CalibrationError naming `source` when the image size is unknown.
  cv::Size requireImageSize() const;
  /// Throws CalibrationError naming `source` when it holds the cameras only (no LiDAR
  /// extrinsics), for the stages that project a scan.
  void requireVelodyne() const;

  /// Throws CalibrationError naming `source` and the key unless the calibration is
  /// physical: P0..P3 finite, fx, fy > 0, third row 0 0 1 (rectified), no skew; an image
  /// size of 0x0 (unknown) or 1..limits::kMaxImageSide a side; T_cam0_velo (and
  /// T_velo_imu when read) rigid; the LiDAR's beam elevations, when listed, one per ring, rising
  /// within -90 .. 90 degrees. loadCalibration and the Reconstructor call it.
  void validate() const;

private:
  [[noreturn]] static void throwNoSuchCamera(int camera);
};

/// Reads a calibration, the format detected from `path`:
///  - a KITTI odometry `calib.txt` (P0..P3, Tr), or a sequence folder holding one; a file of
///    P0..P3 only (the KITTI stereo benchmarks) is a camera-only calibration (has_velodyne);
///  - a KITTI raw date folder (calib_cam_to_cam.txt with P_rect_0X, R_rect_00, S_rect_0X,
///    plus calib_velo_to_cam.txt and, when present, calib_imu_to_velo.txt), a drive folder
///    inside it, or calib_cam_to_cam.txt itself;
///  - a KITTI object `calib/NNNNNN.txt` (P0..P3, R0_rect, Tr_velo_to_cam);
///  - a rig file (rig_file.h), or a folder holding one as rig.yaml, which is read before a
///    calib.txt beside it, as the dataset readers read it;
///  - the project's OpenCV YAML camera file (.yaml/.yml, see saveCalibrationYaml).
/// For odometry and object files, the image size is read from the first image beside the
/// calibration when there is one. A missing key or a matrix with the wrong number of values
/// throws CalibrationError naming key and file; a missing path throws IOError.
Calibration loadCalibration(const std::string& path);
/// The same, with the image size a user gives (a tool's -image_size WxH) where no image lies
/// beside the calibration; {0, 0} = none given. A size that contradicts the calibration's own
/// throws CalibrationError naming both.
Calibration loadCalibration(const std::string& path, cv::Size image_size);

/// The frame id of clouds in a rectified camera's frame ("camera_0" .. "camera_3"); scans of
/// a Sequence are in "velodyne". Stamps are microseconds from the sequence's first frame.
std::string cameraFrameId(int camera);
inline constexpr const char* kVelodyneFrameId = "velodyne";

/// "WxH" (e.g. 1242x375) to a size, "" to {0, 0} (none given); throws InvalidInputError
/// naming the text otherwise.
cv::Size parseImageSize(const std::string& text);

/// Writes the project's YAML camera file (keys P0..P3 as 3x4, image_width, image_height,
/// T_cam0_velo as 4x4 and the LiDAR's description, lidar_sweeping, lidar_rings and
/// lidar_beam_elevations_deg, unless the calibration is camera-only). Atomic: nothing is left
/// behind on failure.
void saveCalibrationYaml(const Calibration& calibration, const std::string& path);

/// Writes a KITTI odometry calib.txt (P0..P3, and Tr unless camera-only). Atomic.
void saveOdometryCalibration(const Calibration& calibration, const std::string& path);

} // namespace msf
