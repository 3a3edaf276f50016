// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>

#include <Eigen/Core>
#include <opencv2/core/types.hpp>
#include <pcl/point_cloud.h>

#include <cmath>
#include <string>

namespace msf {

/// The intrinsics of one rectified camera, in float for per-pixel loops: pixel (u, v) with
/// depth z is the point ((u - cx) z / fx, (v - cy) z / fy, z), as depthImageToCloud makes.
struct PinholeCamera {
  float fx = 0.f, fy = 0.f, cx = 0.f, cy = 0.f;
  int width = 0, height = 0;

  /// fx, fy > 0 and finite, cx, cy finite, a size of at least 1x1.
  bool valid() const {
    return fx > 0.f && fy > 0.f && std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy) &&
           width > 0 && height > 0;
  }
  /// "fx 500.00, fy 500.00, cx 320.00, cy 240.00", for messages.
  std::string intrinsicsText() const;
  /// The same intrinsics and size.
  bool operator==(const PinholeCamera& o) const {
    return fx == o.fx && fy == o.fy && cx == o.cx && cy == o.cy && width == o.width && height == o.height;
  }
  bool operator!=(const PinholeCamera& o) const { return !(*this == o); }
  /// The point the camera sees at pixel (u, v) with depth z, in its frame.
  Eigen::Vector3f point(float u, float v, float z) const { return {(u - cx) * z / fx, (v - cy) * z / fy, z}; }
  /// Camera `camera` (0..3) of a calibration; throws CalibrationError when the calibration
  /// has no image size, InvalidInputError for a camera index out of range.
  static PinholeCamera fromCalibration(const Calibration& calibration, int camera = 0);
  /// The camera of a canvas that holds this camera's image at `image_in_canvas` (imageInCanvas):
  /// the principal point moved by the margins, the canvas's size.
  PinholeCamera onCanvas(const cv::Rect& image_in_canvas, const cv::Size& canvas) const;
};

/// Where an image lies in a canvas grown from it by one margin on the left and right and one on
/// the top and bottom (the LiDAR's canvas, projection.margin_px): the image's pixels, or an empty
/// rectangle when the two sizes are equal. Throws InvalidInputError naming `what` when the canvas
/// is not such a growth of the image.
cv::Rect imageInCanvas(const cv::Size& canvas, const cv::Size& image, const std::string& what);

/// Least-squares fit of u = fx x/z + cx and v = fy y/z + cy over points and their pixels,
/// so that a tool can work on an organized .pcd alone, without its calibration.
class PinholeFit {
public:
  void add(double u, double v, double x, double y, double z);
  void merge(const PinholeFit& other);
  double count() const { return n_; }
  /// The camera of a width x height image. Throws InvalidInputError naming `what` when there
  /// are too few points, or when the RMS residual along u or v exceeds `max_rms_px` (the
  /// points are not on their pixels' rays: real LiDAR returns are within half a pixel).
  PinholeCamera solve(int width, int height, const std::string& what, double max_rms_px = 1.0) const;

private:
  double n_ = 0, sa_ = 0, saa_ = 0, su_ = 0, sau_ = 0, suu_ = 0; // a = x / z against u
  double sb_ = 0, sbb_ = 0, sv_ = 0, sbv_ = 0, svv_ = 0;          // b = y / z against v
};

/// Throws InvalidInputError naming `what` when its points, fitted as `fit`, were made by another
/// camera than `camera` (named by `source`): a ray through a corner of the image lands
/// more than 2 pixels apart in the two, as in a .pcd of another rig of the same image size. A fit
/// that recovers no camera (too few points, points off their rays) says nothing.
void requireCameraOfPoints(const PinholeFit& fit, const PinholeCamera& camera, const std::string& what,
                           const std::string& source);

/// The fit of an organized cloud's valid points (finite, z > 0) against their pixels.
template <typename PointT>
PinholeFit fitPinhole(const pcl::PointCloud<PointT>& cloud);

/// The intrinsics of an organized cloud made by a pinhole camera, fitted over its valid
/// points. Throws InvalidInputError when the cloud is not organized, has too few valid
/// points, or its points are not on their pixels' rays (see PinholeFit::solve).
template <typename PointT>
PinholeCamera estimatePinholeCamera(const pcl::PointCloud<PointT>& cloud, double max_rms_px = 1.0);

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/io/impl/pinhole_camera.hpp>
#endif
