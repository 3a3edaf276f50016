// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/io/calibration.h>
#include <msf/io/pinhole_camera.h>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <memory>
#include <vector>

namespace msf {

/// The settings of LidarProjector: section `projection` of a config file.
struct ProjectionConfig {
  static constexpr const char* kSection = "projection";
  static constexpr const char* kAbout =
      "LidarProjector (paper step 1): the Velodyne scan into a camera's image, nearest return per pixel";
  int camera = 0;
  float min_range_m = 0.f;
  float max_range_m = 120.f;
  /// The canvas (projectToCanvas) keeps returns up to margin_px outside the image, so that
  /// interpolation bridges the gaps that cross the image's edges (the lowest ring of the image
  /// has its neighbour below the image) instead of leaving them open; results are cropped back.
  int margin_px = 16;

  template <class Keys>
  void keys(Keys& k) {
    k("camera", camera, between(0, 3), "rectified camera whose image the scan fills (KITTI's 0..3; the pipeline needs 0)");
    k("min_range_m", min_range_m, atLeast(0), "returns nearer to the LiDAR are dropped, m");
    k("max_range_m", max_range_m, above(0), "returns farther from the LiDAR are dropped, m (HDL-64E: 120)");
    k("margin_px", margin_px, between(0, 256), "border of the canvas around the image whose returns are kept, px");
  }
  /// Throws ConfigError naming the first key out of range.
  void validate() const;
};

/// Paper step 1: a Velodyne scan (PointXYZI, velodyne frame) into one camera's image.
/// Points are moved into the camera's rectified frame and projected with its intrinsics
/// (a precomputed 3x4 matrix in float, one pass); points behind the camera, outside the
/// image or outside [min_range, max_range] (distance from the LiDAR) are dropped, and
/// where several land on one pixel the nearest wins. Pixel centres are integers.
/// The const methods may be called from several threads at once: the work buffers are per
/// thread, reused from scan to scan.
class LidarProjector {
public:
  using Ptr = std::shared_ptr<LidarProjector>;
  using ConstPtr = std::shared_ptr<const LidarProjector>;

  LidarProjector() = default;
  /// Throws CalibrationError when the calibration has no image size, ConfigError for a
  /// bad config.
  explicit LidarProjector(const Calibration& calibration, const ProjectionConfig& config = {});

  void setCalibration(const Calibration& calibration);
  /// Throws ConfigError for an invalid config.
  void setConfig(const ProjectionConfig& config);
  const ProjectionConfig& config() const { return config_; }

  /// Intrinsics and size of the target camera's image.
  const PinholeCamera& camera() const { return camera_; }
  /// The rigid transform from the LiDAR's frame to the projecting camera's.
  const Eigen::Isometry3d& cameraFromLidar() const { return T_camera_velo_; }
  /// The canvas: the image grown by margin_px on every side (principal point shifted).
  PinholeCamera canvasCamera() const;
  /// Where the image lies in the canvas.
  cv::Rect imageInCanvas() const;

  /// Depth image (CV_32FC1, metres along the optical axis, 0 = no return) and, when
  /// `intensity` is given, the reflectance of the winning return (0 elsewhere).
  /// Matrices are reused when they already have the right size and type.
  void projectToImage(const pcl::PointCloud<pcl::PointXYZI>& scan, cv::Mat& depth,
                      cv::Mat* intensity = nullptr) const;
  /// The same on the canvas.
  void projectToCanvas(const pcl::PointCloud<pcl::PointXYZI>& scan, cv::Mat& depth,
                       cv::Mat* intensity = nullptr) const;

  /// Organized cloud of the image's size: each pixel with a return holds that return's
  /// exact position in the camera's rectified frame (within half a pixel of the pixel's
  /// ray) and, when PointT has them, its reflectance and distance 0; other pixels are NaN
  /// (distance +inf) and the cloud is not dense. Instantiated for PointXYZ, PointXYZI and
  /// PointXYZID.
  template <typename PointT>
  void project(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointT>& cloud) const;
  /// The same on the canvas.
  template <typename PointT>
  void projectCanvas(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointT>& cloud) const;

private:
  /// Depth (0 none) of the winning return per pixel of an image grown by `margin`, and
  /// its index in the scan (-1 none) when `winner` is given.
  void scatter(const pcl::PointCloud<pcl::PointXYZI>& scan, int margin, cv::Mat& depth, cv::Mat* winner) const;
  void projectDepth(const pcl::PointCloud<pcl::PointXYZI>& scan, int margin, cv::Mat& depth,
                    cv::Mat* intensity) const;
  template <typename PointT>
  void projectCloud(const pcl::PointCloud<pcl::PointXYZI>& scan, int margin, pcl::PointCloud<PointT>& cloud) const;

  ProjectionConfig config_;
  Calibration calibration_;
  PinholeCamera camera_;
  Eigen::Isometry3d T_camera_velo_ = Eigen::Isometry3d::Identity(); ///< velodyne -> this camera
  Eigen::Matrix<float, 3, 4> T_cam_velo_ = Eigen::Matrix<float, 3, 4>::Zero(); ///< the same, as projected
  float skew_ = 0.f;
  bool calibrated_ = false;
};

} // namespace msf
