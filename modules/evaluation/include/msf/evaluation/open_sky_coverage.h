// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/mesh_view_scoring.h>
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/marching_cubes.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace msf {

/// Evaluation protocol 6 over a sequence: how much of each frame's open sky the mesh covers.
struct SkyCoverage {
  std::size_t frames = 0;          ///< frames with a sky mask and a pose
  std::size_t sky_pixels = 0;      ///< open-sky pixels over those frames
  std::size_t covered_pixels = 0;  ///< of those, pixels where the mesh rendered into the frame has a surface
  double share = 0;                ///< covered_pixels / sky_pixels (0 without sky)
  double mean_frame_share = 0;     ///< the mean of each frame's share, over frames with sky
  double worst_share = 0;          ///< the largest frame's share
  std::size_t worst_frame = 0;     ///< the frame that has it
  double covered_depth_median_m = 0; ///< median depth of the surfaces over the sky (0 without)
  std::map<std::size_t, double> frame_share; ///< per frame with sky
};

/// Protocol 6 (docs/design.md): each frame's open sky (SkyMask) is kept as runs of pixels,
/// with the frame's pose; after the run the mesh is rendered into the camera at every pose
/// (MeshRasterizer: the first surface along each pixel's ray) and the sky pixels it covers are
/// counted. A mesh that holds what the frames saw leaves the sky empty: a surface there is a
/// sheet fused from depth the sky cannot have had.
///
/// A frame's mask and its pose may come from different threads (the pipeline's loading thread
/// computes the mask, its integration thread knows the pose): calls are serialized by one lock.
class OpenSkyCoverage {
public:
  /// Throws InvalidInputError for an invalid camera.
  explicit OpenSkyCoverage(const PinholeCamera& camera);

  /// The open sky of `frame`: CV_8UC1 of the camera's size, non-zero = sky. Throws
  /// InvalidInputError for another type or size, or a frame given twice.
  void addMask(std::size_t frame, const cv::Mat& mask);
  /// The pose of `frame` (mask before or after). Throws InvalidInputError for a pose that is
  /// not finite.
  void setPose(std::size_t frame, const Eigen::Isometry3d& T_world_cam);
  /// Which covering surface points (world frame) count; empty: all of them.
  using SurfaceFilter = std::function<bool(const Eigen::Vector3f&)>;

  /// One mesh's SkyCoverage, counted view by view (addViews).
  class Tally {
  public:
    SkyCoverage coverage() const;

  private:
    friend class OpenSkyCoverage;
    void addFrame(std::size_t index, std::size_t sky_pixels, std::size_t covered);
    SkyCoverage out_;
    double share_sum_ = 0;
    std::vector<float> covered_depth_;
  };

  /// Renders `mesh` (world frame) at the pose of every frame that has a mask and counts the sky
  /// it covers; with `counts`, only the pixels whose covering surface point it accepts (e.g.
  /// those off a true surface: a sheet, not a blurred outline). Frames without a pose (a run
  /// stopped early) are left out.
  SkyCoverage scoreMesh(const TriangleMesh& mesh, const SurfaceFilter& counts = {});
  /// The same through `views`, whose renderings other scorers of the same frames share (several
  /// filters, several protocols): the sky each frame's view of the mesh covers is counted into
  /// `tally` (which must outlive `views`' scoring), with `counts` as in scoreMesh.
  void addViews(MeshViewScoring& views, Tally& tally, const SurfaceFilter& counts = {});

  /// A picture of one frame: `image` (CV_8UC1 or CV_8UC3 of the camera's size) with its open
  /// sky tinted cyan and the sky a mesh covers (`rendered`: depth, > 0 where a surface is) in
  /// red. Throws InvalidInputError for images of another size.
  static cv::Mat drawCoverage(const cv::Mat& image, const cv::Mat& mask, const cv::Mat& rendered);

  std::size_t frames() const;

private:
  struct FrameSky {
    std::vector<std::uint32_t> runs; ///< pairs: first pixel (v * width + u), length
    std::size_t pixels = 0;
    bool has_mask = false, has_pose = false;
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  };

  PinholeCamera camera_;
  mutable std::mutex mutex_;
  std::map<std::size_t, FrameSky> frames_;
};

} // namespace msf
