// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>

#include <opencv2/core/mat.hpp>
#include <pcl/filters/filter.h>

namespace msf {

/// Common shape of the stages that turn a sparse organized cloud (projected LiDAR) into a
/// dense one of the same size: the input's depth image is completed by `completeDepth`,
/// then every pixel with an estimate becomes a point on its pixel's ray. Real returns that
/// keep their depth keep their exact point; a new point takes the other fields (intensity,
/// colour) of the nearest real return. When PointT has a `distance` field (PointXYZID) it
/// receives the exact distance in pixels to the nearest real return, also where there is
/// no estimate (+inf when the input has no return at all). With setIndices (PCL's
/// convention), only the indexed points are returns to complete from; the output is still the
/// whole organized cloud, and the other points are treated as pixels without a return.
template <typename PointT>
class DepthCompletionFilter : public pcl::Filter<PointT> {
public:
  using Ptr = pcl::shared_ptr<DepthCompletionFilter<PointT>>;
  using ConstPtr = pcl::shared_ptr<const DepthCompletionFilter<PointT>>;

  using PointCloud = typename pcl::Filter<PointT>::PointCloud;

  /// Intrinsics of the camera the cloud is organized by. When unset (the default), they
  /// are estimated from the input's points (estimatePinholeCamera) at every call, to the
  /// points' float precision: the new points' x and y then differ from the exact camera's by
  /// a fraction of a millimetre. Set it for exact rays (LidarCompletion does).
  void setCamera(const PinholeCamera& camera) { camera_ = camera; }
  const PinholeCamera& getCamera() const { return camera_; }

  /// The depth images of the last call (CV_32FC1, 0 = none): input and completed.
  const cv::Mat& sparseDepth() const { return sparse_; }
  const cv::Mat& denseDepth() const { return dense_; }

protected:
  /// Throws InvalidInputError when the input is not organized or does not match the camera.
  void applyFilter(PointCloud& output) override;
  /// sparse: CV_32FC1 (0 = none) -> dense: CV_32FC1 (0 = none), same size.
  virtual void completeDepth(const cv::Mat& sparse, cv::Mat& dense) = 0;
  /// At most this many threads of OpenCV's pool (0: all of them).
  virtual int threads() const { return 0; }
  /// Clears the depth of the points that setIndices left out (none without it). Throws
  /// InvalidInputError for an index outside the cloud.
  void keepIndexedReturns(cv::Mat& sparse) const;

  using pcl::Filter<PointT>::input_;
  using pcl::Filter<PointT>::indices_;
  using pcl::Filter<PointT>::fake_indices_;
  using pcl::Filter<PointT>::filter_name_;

  PinholeCamera camera_;
  cv::Mat sparse_, dense_, distance_, nearest_;
};

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/range_image/impl/depth_completion_filter.hpp>
#endif
