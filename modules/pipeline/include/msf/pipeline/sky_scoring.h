// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/open_sky_coverage.h>
#include <msf/fusion/sky_mask.h>
#include <msf/io/calibration.h>
#include <msf/io/frame_source.h>
#include <msf/range_image/lidar_projector.h>

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace msf {

/// Evaluation protocol 6 over a run: each frame's open sky (SkyMask of the colour image, or the
/// grey one without colour, and of the whole scan projected into camera 0) before any stage
/// sees the frame, its pose after integration, and after the run the meshes rendered at every
/// pose (OpenSkyCoverage). Pictures of chosen frames show the sky and what covers it.
/// addFrame runs on the engine's loading thread, setPose on its integration thread.
class SkyScoring {
public:
  /// `picture_frames`: frames whose image and mask are kept for drawPictures.
  SkyScoring(const Calibration& calibration, const ProjectionConfig& projection, std::set<std::size_t> picture_frames);

  /// The frame's open sky, from its whole scan (call it before a ring hold-out takes rings away).
  void addFrame(const Frame& frame);
  /// The open sky of a frame (CV_8UC1, 255 = sky): SkyMask of its colour image where it has
  /// camera 0's size, else of the grey one, and of its whole scan projected into camera 0.
  cv::Mat maskOf(const Frame& frame);
  void setPose(std::size_t frame, const Eigen::Isometry3d& T_world_cam);
  /// Each mesh (by name: "mesh", "mesh_lidar", ...) rendered at every pose.
  std::map<std::string, SkyCoverage> score(const std::map<std::string, const TriangleMesh*>& meshes);
  /// The same for the mesh `views` renders, its sky counted anew as `name` in scores(): the
  /// views are shared with the other scorers of the frames. `with_pictures`: the mesh's
  /// renderings at the picture frames are kept for drawPictures.
  void addViews(MeshViewScoring& views, const std::string& name, bool with_pictures = false);
  /// What addViews counted, by name, once `views` scored.
  std::map<std::string, SkyCoverage> scores() const;
  /// sky_NAME.png in `dir` for each picture frame whose rendering addViews kept
  /// (OpenSkyCoverage::drawCoverage), NAME from `names`; returns the file names written.
  std::vector<std::string> drawPictures(const std::string& dir, const std::map<std::size_t, std::string>& names);

private:
  const cv::Mat& imageOf(const Frame& frame) const;

  struct Picture {
    cv::Mat image, mask;
    bool has_pose = false;
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
    cv::Mat rendered; ///< the mesh's depth seen from the pose (addViews with pictures)
  };
  PinholeCamera camera_;
  LidarProjector projector_;
  SkyMask mask_;
  OpenSkyCoverage coverage_;
  std::set<std::size_t> picture_frames_;
  std::mutex mutex_;
  std::map<std::size_t, Picture> pictures_;
  std::map<std::string, OpenSkyCoverage::Tally> tallies_;
  cv::Mat returns_;
};

} // namespace msf
