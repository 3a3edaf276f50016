// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/surface_classes.h>
#include <msf/synthetic/moving_box.h>

#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace msf::synthetic {

/// Reads the exact ground truth msf_synth writes beside its KITTI odometry layout:
///   gt/depth_0/NNNNNN.png    camera 0 depth z, KITTI 16-bit (metres x 256, 0 = none)
///   gt/disp_0/NNNNNN.png     grey-pair disparity f B / z, KITTI 16-bit (pixels x 256)
///   gt/obj_map_0/NNNNNN.png  8-bit: 0 background, 1..255 foreground (cars, poles, people),
///                            KITTI 2015's obj_map convention
///   gt/moving_0/NNNNNN.png   8-bit: 255 where the pixel sees a moving object, 0 elsewhere
///                            (also beyond 255 m, where depth and obj_map have none)
///   gt/moving_objects.txt    the moving objects' oriented boxes at every frame (MovingBox)
///   gt/scene.ply             the true static surface (no moving objects), world = camera 0
///                            at frame 0 (poses/00.txt)
///   gt/scene_classes.txt     what each of scene.ply's vertices is (SurfaceClasses)
/// Frames are in file-name order, the same order as msf::Sequence's frames.
class GroundTruth {
public:
  /// `path` is a dataset root holding gt/, a sequence folder inside it (root/sequences/00),
  /// or the gt folder itself. Throws IOError naming `path` when no ground truth is found.
  explicit GroundTruth(const std::string& path);

  /// The gt folder for `path` (see the constructor), or "" when there is none.
  static std::string find(const std::string& path);

  const std::string& directory() const { return dir_; }
  std::size_t size() const { return names_.size(); }
  /// File stem of frame i ("000042"); throws InvalidInputError when out of range.
  const std::string& frameName(std::size_t i) const;
  /// Index of the frame with this file stem; throws InvalidInputError when absent.
  std::size_t indexOf(const std::string& frame_name) const;

  std::string depthPath(std::size_t i) const;
  std::string disparityPath(std::size_t i) const;
  std::string objectMapPath(std::size_t i) const;
  std::string movingMaskPath(std::size_t i) const;
  std::string movingBoxesPath() const;
  std::string sceneMeshPath() const;
  std::string sceneClassesPath() const;
  /// True when gt/scene_classes.txt exists (datasets written before it have none).
  bool hasSceneClasses() const;
  /// gt/scene_classes.txt for a scene.ply of `vertices` vertices. Throws IOError naming the
  /// file when it is missing, garbled or covers another number of vertices.
  SurfaceClasses sceneClasses(std::size_t vertices) const;
  /// True when the dataset marks moving objects (gt/moving_0/ exists).
  bool hasMovingMasks() const;

  /// CV_32F metres, 0 = none.
  cv::Mat depth(std::size_t i) const;
  /// CV_32F pixels, 0 = none.
  cv::Mat disparity(std::size_t i) const;
  /// CV_8U, 0 = background.
  cv::Mat objectMap(std::size_t i) const;
  /// The pixels of frame i with ground truth (depth > 0) split as the KITTI devkit splits its
  /// error: CV_8U masks (255 = in) of the background and of the foreground (objectMap > 0).
  struct Split {
    cv::Mat background, foreground;
  };
  /// `depth`: the frame's depth(i), when the caller has read it already (read here otherwise).
  /// Throws IOError when the object map and the depth differ in size.
  Split split(std::size_t i, const cv::Mat& depth = cv::Mat()) const;
  /// CV_8U, 255 where the pixel sees a moving object. A dataset written before moving
  /// objects existed has no moving_0/: its street was static, and the mask is all zero
  /// (of the depth's size). Throws IOError when moving_0/ exists and the frame's file does
  /// not, or its size is not the depth's.
  cv::Mat movingMask(std::size_t i) const;
  /// The moving objects' boxes at every frame, in file order (frame by frame). Throws
  /// IOError naming the file when it is missing (datasets written before moving objects
  /// have none), and the file and line when a line is garbled.
  std::vector<MovingBox> movingBoxes() const;

private:
  std::string dir_;
  std::vector<std::string> names_;
};

} // namespace msf::synthetic
