// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>

#include <opencv2/core/mat.hpp>
#include <pcl/PCLPointCloud2.h>
#include <pcl/point_cloud.h>

#include <string>

namespace msf {

/// What TsdfIntegrator consumes: a depth image with its camera, and optionally a colour
/// image and a per-pixel weight image of the same size (the fusion stage's confidence).
/// The integrator works on this form whatever the point type of the input cloud, so its
/// inner loop is compiled once.
struct DepthFrame {
  cv::Mat depth;   ///< CV_32FC1, z in metres; 0 or NaN = no depth
  cv::Mat color;   ///< CV_8UC3 in OpenCV's BGR order, or empty
  cv::Mat weight;  ///< CV_32FC1 (>= 0), or empty
  /// CV_32FC1 (>= 0): the weight of the free space in front of each pixel's depth, for space
  /// carving; empty: the weight's. The fusion's differs where it averaged two samples that
  /// disagree: where the surface is is uncertain, that the ray passed in front of both is not.
  cv::Mat free_space_weight;
  PinholeCamera camera;

  /// Throws InvalidInputError naming the image that has a wrong type or size, or the camera
  /// when its intrinsics are invalid or its size differs from the depth image.
  void validate() const;
};

/// Organized cloud (NaN where there is no depth) to a DepthFrame: depth = z; colour from the
/// rgb field when PointT has one; weight and free-space weight from float fields named
/// `weight` and `free_space_weight` when PointT has them (pcl::traits::has_field), as the
/// fusion stage's point type does. `camera` = nullptr
/// recovers the intrinsics from the cloud (estimatePinholeCamera). Instantiated for PCL's
/// PointXYZ, PointXYZI, PointXYZRGB, PointXYZRGBA and the stages' PointXYZID,
/// PointXYZRGBConfidence and PointXYZRGBWeight (MSF_NO_PRECOMPILE for other types).
/// Throws InvalidInputError when the cloud is not organized.
template <typename PointT>
DepthFrame toDepthFrame(const pcl::PointCloud<PointT>& cloud, const PinholeCamera* camera = nullptr);

/// Same from a cloud of any point type as read from a file (fields x y z, optional rgb or
/// rgba, optional weight and free_space_weight), so tools accept every organized cloud the other stages write.
/// `what` names the cloud in messages. Also throws InvalidInputError when its points were made by
/// another camera than `camera` (requireCameraOfPoints): a .pcd of another rig of the same size.
DepthFrame toDepthFrame(const pcl::PCLPointCloud2& cloud, const PinholeCamera* camera = nullptr,
                        const std::string& what = "cloud");

/// The field `sky_depth` of an organized cloud (the fused cloud's: NaN where the pixel is not
/// open sky, else the depth in front of which its ray is carved, +inf for the whole ray) as a
/// CV_32FC1 image of the cloud's size, as TsdfIntegrator::carveSky takes it; empty when the cloud
/// has no such field. Throws InvalidInputError naming `what` when the field is not one float32,
/// the cloud is not organized or a pixel's bound is neither NaN nor above 0 (checkSkyDepthBounds).
cv::Mat readSkyDepth(const pcl::PCLPointCloud2& cloud, const std::string& what = "cloud");

/// Throws InvalidInputError, naming `what` and the first pixel at fault, where `sky_depth`
/// (CV_32FC1) holds a bound that is neither NaN (not sky) nor above 0 (a depth; +inf: the whole
/// ray).
void checkSkyDepthBounds(const cv::Mat& sky_depth, const std::string& what);

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/reconstruction/impl/depth_frame.hpp>
#endif
