// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/depth_image_fusion.h>
#include <msf/fusion/fusion_config.h>
#include <msf/fusion/point_types.h>
#include <msf/io/calibration.h>
#include <msf/range_image/point_types.h>
#include <msf/stereo/point_types.h>

#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>

#include <memory>
#include <vector>

namespace msf {

/// Paper step 4: per-pixel fusion of two organized depth clouds of one camera, the
/// interpolated LiDAR and the stereo depth, into one organized cloud of the same size, in
/// the shape of PCL's two-input classes (pcl::Registration's setInputSource/Target):
///
///   msf::DepthFusion<> fusion;                       // PointXYZID + PointXYZRGBConfidence
///   fusion.setCalibration(calibration);              // f B of the grey pair
///   fusion.setInputLidar(interpolated);              // CompoundInterpolation's output
///   fusion.setInputStereo(stereo);                   // SgbmStereo's output
///   pcl::PointCloud<msf::PointXYZRGBWeight> fused;
///   fusion.fuse(fused);
///
/// The clouds' depths are fused by DepthImageFusion, the model the pipeline applies
/// (fusion_model.h: eq. 6 or inverse-variance). The LiDAR type's `distance` field (pixels to
/// the nearest real return) and the stereo type's `confidence` feed the weights; a type
/// without them counts as real returns (distance 0) and as fully confident matches. A fused
/// point lies on the ray of its input point (stereo's where it has one, else its pixel's);
/// colour comes from the stereo point, or, when setInputColor was given, from the colour image
/// by projection (colorizeDepth, with the grey image where the colour camera does not see).
/// An output type with the fields writes the fused `weight`, `free_space_weight` and
/// `sky_depth` (PointXYZRGBWeight). Pixels without depth are NaN, and then the cloud is not
/// dense. The header (frame id, stamp) is the stereo cloud's.
///
/// A LiDAR cloud of the LiDAR's canvas (LidarCompletion::computeCanvas: the image with a margin
/// on every side) gives an output of the canvas's size: the image's pixels fused, the margin the
/// LiDAR's, as the map integrates a frame (growOntoCanvas).
template <typename PointLidarT = PointXYZID, typename PointStereoT = PointXYZRGBConfidence,
          typename PointOutT = PointXYZRGBWeight>
class DepthFusion {
public:
  using Ptr = std::shared_ptr<DepthFusion<PointLidarT, PointStereoT, PointOutT>>;
  using ConstPtr = std::shared_ptr<const DepthFusion<PointLidarT, PointStereoT, PointOutT>>;

  using PointCloudLidar = pcl::PointCloud<PointLidarT>;
  using PointCloudLidarConstPtr = typename PointCloudLidar::ConstPtr;
  using PointCloudStereo = pcl::PointCloud<PointStereoT>;
  using PointCloudStereoConstPtr = typename PointCloudStereo::ConstPtr;
  using PointCloudOut = pcl::PointCloud<PointOutT>;

  DepthFusion() = default;
  explicit DepthFusion(const DepthFusionConfig& config) { setConfig(config); }

  /// Throws ConfigError naming the key of a value out of range.
  void setConfig(const DepthFusionConfig& config) {
    config.validate();
    config_ = config;
  }
  const DepthFusionConfig& getConfig() const { return config_; }
  void setMethod(FusionMethod method) { config_.method = method; }
  FusionMethod getMethod() const { return config_.method; }

  /// Gives f B for the disparity domain, and the colour camera's projection.
  void setCalibration(const Calibration& calibration);
  const Calibration& getCalibration() const { return calibration_; }

  void setInputLidar(const PointCloudLidarConstPtr& cloud) { lidar_ = cloud; }
  const PointCloudLidarConstPtr& getInputLidar() const { return lidar_; }
  void setInputStereo(const PointCloudStereoConstPtr& cloud) { stereo_ = cloud; }
  const PointCloudStereoConstPtr& getInputStereo() const { return stereo_; }

  /// Optional image of the colour camera (BGR) to colour every fused point by projection,
  /// also where only the LiDAR has depth. Empty: colour from the stereo points. Of the clouds'
  /// size, it is also where fusion.clear_sky finds the open sky (else in setInputImage's).
  void setInputColor(const cv::Mat& image) { color_ = image; }
  /// Optional grey image of camera 0 (CV_8UC1, the clouds' width x height): with it and
  /// fusion.facade_extension, a LiDAR-backed wall goes on upward over the blank pixels above
  /// it (extendFacades), as in the pipeline; and with fusion.clear_sky no depth in its clear
  /// sky (withholdClearSky), which decides near an edge when a colour image of its size is set.
  /// Empty: nothing after the fusion but edge support.
  void setInputImage(const cv::Mat& left) { left_ = left; }
  void setColorCamera(int camera) { color_camera_ = camera; }
  int getColorCamera() const { return color_camera_; }
  /// Whether fuse() fills the image's small holes at weight 0 (fusion.hole_fill_px, never in the
  /// open sky; DepthImageFusion::fillSmallHoles): the depth the engine gives once the map took
  /// the frame, which an integrator ignores. Off by default: the fusion's own depth.
  void setFillSmallHoles(bool fill) { fill_small_holes_ = fill; }
  bool getFillSmallHoles() const { return fill_small_holes_; }

  /// Fuses the inputs into `output` (resized to the LiDAR cloud's width x height).
  /// Throws InvalidInputError naming the input that is missing, not organized, or of
  /// another size than the other (or its canvas) or the calibration's images, or a stereo
  /// depth whose confidence is not 0..1 (NaN); CalibrationError when no calibration was set.
  void fuse(PointCloudOut& output);

private:
  // The steps of fuse().
  void checkInputs();
  /// The clouds' depths, the LiDAR's distance to a real return and the stereo's confidence as
  /// images (the LiDAR's over its whole cloud, the canvas when it is one).
  void readImages();
  /// Paper step 4 on the images (DepthImageFusion), the colours and the open sky, grown onto the
  /// LiDAR's canvas when it is one.
  void fuseImages();
  /// The stereo points' colours as a BGR image (black for a type without colour).
  void readStereoColours(cv::Mat& bgr) const;
  /// The fused points on the rays of the input points; the header of the stereo cloud's.
  void writePoints(PointCloudOut& output) const;

  DepthFusionConfig config_;
  Calibration calibration_;
  bool has_calibration_{false};
  PointCloudLidarConstPtr lidar_;
  PointCloudStereoConstPtr stereo_;
  cv::Mat color_, left_;
  int color_camera_{2};
  bool fill_small_holes_{false};
  cv::Rect image_in_canvas_; ///< where the stereo's image lies in the LiDAR cloud; empty: the same size
  DepthImageFusion image_fusion_;
  // Work buffers, kept between frames.
  cv::Mat lidar_depth_, lidar_distance_, stereo_depth_, stereo_confidence_;
  cv::Mat fused_depth_, fused_weight_, fused_free_weight_, fused_color_, sky_, sky_depth_;
};

} // namespace msf

#ifdef MSF_NO_PRECOMPILE
#include <msf/fusion/impl/depth_fusion.hpp>
#endif
