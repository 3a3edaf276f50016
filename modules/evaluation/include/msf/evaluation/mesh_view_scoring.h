// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/mesh_rasterizer.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <functional>
#include <map>
#include <vector>

namespace msf {

/// The scorers of a mesh rendered at frames' poses (protocol 4's ground truth, protocol 6's
/// open sky, a synthetic sequence's true sky) share each rendering: a view, one camera at one
/// pose, is rendered once (MeshRasterizer: the first surface along each pixel's ray) and handed
/// to every scorer that looks through it. Views are rendered one at a time in frame order, so
/// a long sequence holds one rendering, not one per frame. A scorer that reads only the top rows
/// of an image (the sky) says so, and a view none of whose scorers reads more renders only those.
class MeshViewScoring {
public:
  /// Scores one view: the frame and the mesh's depth seen from it (CV_32FC1 of the camera's
  /// width, z in metres, 0 where no surface): the image's top rows, as many as the view's
  /// scorers read (all of them, unless every scorer gave top_rows).
  using Scorer = std::function<void(std::size_t frame, const cv::Mat& rendered)>;

  /// `scorer` looks through `camera` at the frames of `views` (frame -> T_world_cam). A frame
  /// another scorer looks at through the same camera from the same pose shares its view.
  /// `top_rows`: of the frames it lists, the scorer reads only that many rows from the top
  /// (1 .. the camera's height). Throws InvalidInputError for an invalid camera, a pose that is
  /// not finite or rows out of range.
  void add(const PinholeCamera& camera, const std::map<std::size_t, Eigen::Isometry3d>& views, Scorer scorer,
           const std::map<std::size_t, int>& top_rows = {});

  /// Renders `mesh` (world frame) at every view once and hands the rendering to each scorer of
  /// that view; returns how many views were rendered.
  std::size_t score(const TriangleMesh& mesh);

  /// The views to render: fewer than the scorers' frames when they share.
  std::size_t views() const;

private:
  struct View {
    PinholeCamera camera;
    Eigen::Isometry3d T_world_cam;
    int rows = 0;                     ///< the most its scorers read, from the top
    std::vector<std::size_t> scorers; ///< indices into scorers_
  };
  std::vector<Scorer> scorers_;
  std::map<std::size_t, std::vector<View>> views_; ///< by frame: one per camera and pose
  MeshRasterizer rasterizer_;
  cv::Mat rendered_;
};

} // namespace msf
