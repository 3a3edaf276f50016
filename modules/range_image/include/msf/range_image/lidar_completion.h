// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/range_image/compound_interpolation.h>
#include <msf/range_image/depth_interpolator.h>
#include <msf/range_image/ip_basic.h>
#include <msf/range_image/ip_basic_completion.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/range_image/point_types.h>

#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <memory>
#include <string>

namespace msf {

/// The ways a sparse LiDAR projection becomes dense depth.
enum class CompletionMethod {
  Compound,         ///< compound interpolation (InterpolationConfig as configured)
  Linear,           ///< the same slices, linear only
  Cubic,            ///< the same slices, zero-slope cubic only
  IpBasicFast,      ///< IP-Basic fill_in_fast
  IpBasicMultiscale ///< IP-Basic fill_in_multiscale
};
/// "compound" (or "interpolated"), "linear", "cubic", "ipbasic", "ipbasic_multiscale";
/// throws InvalidInputError naming the text otherwise.
CompletionMethod parseCompletionMethod(const std::string& name);
const char* toString(CompletionMethod method);

/// Paper steps 1 and 2 from a raw scan, in memory: the scan is projected onto the canvas
/// (the image grown by projection.margin_px, so that gaps across the image's edges are
/// bridged by the returns just outside it), completed, and cropped to the image. Work
/// buffers are kept between scans; one object per thread.
///
///   msf::LidarCompletion lidar(calibration);             // compound interpolation, camera 0
///   lidar.computeDepth(*scan, depth, &distance);         // CV_32F metres, CV_32F pixels
///   lidar.compute(*scan, cloud);                         // organized msf::PointXYZID
class LidarCompletion {
public:
  using Ptr = std::shared_ptr<LidarCompletion>;
  using ConstPtr = std::shared_ptr<const LidarCompletion>;

  /// Throws CalibrationError or ConfigError naming what is wrong.
  explicit LidarCompletion(const Calibration& calibration, CompletionMethod method = CompletionMethod::Compound,
                           const ProjectionConfig& projection = {}, const InterpolationConfig& interpolation = {},
                           const IpBasicConfig& ip_basic = {});

  /// Dense depth of the camera's image (CV_32FC1, metres, 0 = none) and, when asked, the
  /// distance in pixels from each pixel to the nearest real return (CV_32FC1, +inf when
  /// the scan has none in the canvas).
  void computeDepth(const pcl::PointCloud<pcl::PointXYZI>& scan, cv::Mat& depth, cv::Mat* distance = nullptr);

  /// The whole canvas of the last computeDepth (the image and its margin): depth, and the
  /// distance to the nearest real return when computeDepth was asked for it. Views of work
  /// buffers, valid until the next call.
  const cv::Mat& canvasDepth() const { return dense_; }
  const cv::Mat& canvasDistance() const { return distance_; }

  /// The organized cloud of the image: real returns keep their exact points, the others
  /// lie on their pixels' rays with the reflectance of the nearest return; `distance` as
  /// above (0 on real returns).
  void compute(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointXYZID>& cloud);
  /// The same over the whole canvas (the image and its margin, projector().canvasCamera()): the
  /// LiDAR depth that the map integrates around the fused image (growOntoCanvas).
  void computeCanvas(const pcl::PointCloud<pcl::PointXYZI>& scan, pcl::PointCloud<PointXYZID>& cloud);

  CompletionMethod method() const { return method_; }
  const LidarProjector& projector() const { return projector_; }
  /// Camera of the output image.
  const PinholeCamera& camera() const { return projector_.camera(); }

private:
  void complete(const cv::Mat& sparse, cv::Mat& dense);

  CompletionMethod method_;
  LidarProjector projector_;
  DepthInterpolator interpolator_;
  IpBasicConfig ip_basic_;
  cv::Mat sparse_, dense_, distance_;
  pcl::PointCloud<PointXYZID>::Ptr canvas_;
  pcl::PointCloud<PointXYZID> canvas_out_;
  CompoundInterpolation<PointXYZID> compound_filter_;
  IpBasicCompletion<PointXYZID> ip_basic_filter_;
};

} // namespace msf
