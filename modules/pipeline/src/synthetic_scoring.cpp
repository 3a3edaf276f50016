// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/fusion/sky_mask.h>
#include <msf/io/cloud_io.h>
#include <msf/io/pinhole_camera.h>
#include <msf/pipeline/synthetic_scoring.h>
#include <msf/synthetic/kitti_rig.h>

#include <algorithm>
#include <filesystem>
#include <optional>

namespace msf {

namespace {
constexpr double kGhostDistanceM = 0.2; // farther than this from the static surface: not the road under a car
constexpr std::size_t kCrumbTriangles = 50; // a piece this small is a speck to the eye (a few voxels' faces)
// Crumbs counted by the frames since their place was left: 1, 2, 3 or more. Letting a place go takes
// marching_cubes.component_release_passes frames looking through it, once the object is a
// truncation behind it.
constexpr std::size_t kCrumbAgeBuckets = 3;
constexpr float kOffSurfaceM = static_cast<float>(kGhostDistanceM); // off the true surface: a sheet, not an outline

/// How many frames before `last_frame` moving objects left a place: `last_frame` less the latest
/// frame up to it whose box (gt/moving_objects.txt), grown by `margin_m` (a car's surface is
/// meshed up to a voxel off its box), holds the place; 0 where no box ever held it or one of
/// `last_frame`'s does. Where a car stands when the run ends is what the last frame saw, a true
/// surface; frames the run never reached are not its past.
FramesSinceLeft framesSinceLeft(std::vector<synthetic::MovingBox> boxes, std::size_t last_frame, double margin_m) {
  boxes.erase(std::remove_if(boxes.begin(), boxes.end(), [&](const auto& box) { return box.frame > last_frame; }),
              boxes.end());
  return [boxes = std::move(boxes), last_frame, margin_m](const Eigen::Vector3f& p) -> std::size_t {
    const Eigen::Vector3d q = p.cast<double>();
    std::optional<std::size_t> latest;
    for (const auto& box : boxes)
      if (box.contains(q, margin_m))
        latest = std::max(latest.value_or(box.frame), box.frame);
    return latest ? last_frame - *latest : 0;
  };
}
} // namespace

const std::vector<double>& SyntheticScoring::offSurfaceBands() {
  static const std::vector<double> edges = {2.0, 5.0};
  return edges;
}

SyntheticScoring::SyntheticScoring(const std::string& ground_truth_dir, bool score_meshes, double voxel_size_m)
    : truth_(std::make_unique<synthetic::GroundTruth>(ground_truth_dir)), score_meshes_(score_meshes),
      lidar_(voxel_size_m) {
  if (!score_meshes_)
    return;
  loadMesh(truth_->sceneMeshPath(), scene_);
  static_surface_ = std::make_unique<SurfaceDistance>(scene_);
  if (truth_->hasSceneClasses())
    classes_ = truth_->sceneClasses(static_cast<std::size_t>(scene_.cloud.width) * scene_.cloud.height);
}

cv::Mat SyntheticScoring::depth(const std::string& frame_name) const {
  return truth_->depth(truth_->indexOf(frame_name));
}

void SyntheticScoring::addDepth(const std::string& method, const std::string& frame_name, const cv::Mat& true_depth,
                                const cv::Mat& estimate, double focal_baseline) {
  addDepth(method, truth_->split(truth_->indexOf(frame_name), true_depth), true_depth, estimate, focal_baseline);
}

void SyntheticScoring::addDepth(const std::string& method, const synthetic::GroundTruth::Split& split,
                                const cv::Mat& true_depth, const cv::Mat& estimate, double focal_baseline) {
  all_[method].add(true_depth, estimate, focal_baseline);
  background_[method].add(true_depth, estimate, focal_baseline, split.background);
  foreground_[method].add(true_depth, estimate, focal_baseline, split.foreground);
}

void SyntheticScoring::addScan(const Frame& frame) {
  if (!score_meshes_ || !frame.scan)
    return;
  const std::lock_guard<std::mutex> lock(scans_mutex_);
  scans_[frame.index] = frame.scan;
}

void SyntheticScoring::addFrame(const FrameResult& r, const cv::Mat& true_depth, const Calibration& calibration,
                                double max_depth_m, const cv::Mat& moving_mask) {
  const double fb = calibration.focalBaseline();
  const std::size_t gt_index = truth_->indexOf(r.name);
  const synthetic::GroundTruth::Split split = truth_->split(gt_index, true_depth); // for every method
  const std::pair<const char*, cv::Mat> methods[] = {
      {"sgbm", r.stereo_depth}, {"interpolated", r.lidar_depth}, {"fused", r.fused.depth}};
  for (const auto& [name, estimate] : methods)
    addDepth(name, split, true_depth, estimate, fb);
  if (!score_meshes_)
    return;
  last_frame_ = std::max(last_frame_.value_or(gt_index), gt_index);
  if (!true_sky_)
    true_sky_ = std::make_unique<OpenSkyCoverage>(PinholeCamera::fromCalibration(calibration, 0));
  // The exact sky (no surface along the pixel's ray), less the border protocol 6's mask leaves.
  cv::Mat sky = true_depth == 0.f;
  SkyMask().takeBorder(sky);
  true_sky_->addMask(r.index, sky);
  true_sky_->setPose(r.index, r.T_world_cam0);
  pcl::PointCloud<pcl::PointXYZI>::ConstPtr scan;
  {
    const std::lock_guard<std::mutex> lock(scans_mutex_);
    const auto it = scans_.find(r.index);
    if (it != scans_.end()) {
      scan = it->second;
      scans_.erase(it);
    }
  }
  if (scan)
    lidar_.addScan(*scan, r.T_world_cam0 * calibration.T_cam0_velo);
  // Every 4th pixel of the true static surface in range, for the mesh's completeness against
  // gt/scene.ply: a moving car's pixels are where it was at that frame, not part of the map.
  const cv::Mat moving = moving_mask.empty() ? truth_->movingMask(gt_index) : moving_mask;
  const PinholeCamera camera = PinholeCamera::fromCalibration(calibration, 0);
  const Eigen::Isometry3f T = r.T_world_cam0.cast<float>();
  for (int v = 0; v < true_depth.rows; v += 4)
    for (int u = 0; u < true_depth.cols; u += 4) {
      const float z = true_depth.at<float>(v, u);
      if (z > 0.f && z <= max_depth_m && moving.at<std::uint8_t>(v, u) == 0) {
        seen_surface_.push_back(T * camera.point(static_cast<float>(u), static_cast<float>(v), z));
        seen_depth_.push_back(z);
      }
    }
}

std::map<std::string, SyntheticScoring::MeshScores>
SyntheticScoring::scoreMeshes(const std::map<std::string, MeshToScore>& meshes, double voxel_size_m) const {
  std::map<std::string, MeshScores> scores;
  if (!score_meshes_ || meshes.empty())
    return scores;
  FramesSinceLeft since_left;
  MovingSpace was_moving;
  if (std::filesystem::exists(truth_->movingBoxesPath()) && last_frame_) {
    since_left = framesSinceLeft(truth_->movingBoxes(), *last_frame_, voxel_size_m);
    was_moving = [&since_left](const Eigen::Vector3f& p) { return since_left(p) > 0; };
  }
  const SurfaceDistance& static_surface = *static_surface_;
  // The street's road in its world (y down): the camera's height below the cameras' path.
  const Eigen::Hyperplane<float, 3> road(Eigen::Vector3f(0.f, -1.f, 0.f),
                                         static_cast<float>(synthetic::kCameraHeightM));
  // The nearest distance each piece of the seen surface was seen from (cells of a voxel):
  // what a frame far away cannot place within the completeness threshold.
  const std::vector<float> view_distance =
      nearestViewDistance(seen_surface_, seen_depth_, static_cast<float>(voxel_size_m));
  for (const auto& [name, m] : meshes) {
    if (!m.polygons)
      continue;
    // Marching cubes' meshes weigh their vertices: also scored as the bar on them rises.
    const std::vector<float>& weights = m.mesh->weights;
    MeshScores& s = scores[name];
    s.accuracy = evaluateMesh(*m.polygons, scene_, seen_surface_, 2.0 * voxel_size_m, 1.0, 200000, &view_distance,
                              weights.size() == m.mesh->vertices.size() ? &weights : nullptr,
                              classes_ ? &*classes_ : nullptr);
    if (was_moving) {
      s.ghosts = measureGhosts(m.mesh->vertices, static_surface, was_moving, kGhostDistanceM);
      s.crumbs = measureCrumbs(*m.mesh, static_surface, was_moving, kCrumbTriangles, kGhostDistanceM, since_left,
                               kCrumbAgeBuckets);
      s.has_ghosts = true;
    }
    s.off_surface = splitOffSurface(*m.mesh, static_surface, road, lidar_, kGhostDistanceM, offSurfaceBands());
  }
  return scores;
}

void SyntheticScoring::addTrueSkyViews(MeshViewScoring& views, TrueSky& tally) const {
  if (!true_sky_)
    return;
  const SurfaceDistance& surface = *static_surface_;
  true_sky_->addViews(views, tally.all);
  true_sky_->addViews(views, tally.sheets, [&surface](const Eigen::Vector3f& p) {
    return surface.distance(p, 2.f * kOffSurfaceM) > kOffSurfaceM;
  });
}

void SyntheticScoring::writeDepthScores(RunReport& report) const {
  for (const auto& [name, acc] : all_) {
    auto& d = report.depth[name];
    d.all = acc.metrics();
    d.background = background_.at(name).metrics();
    d.foreground = foreground_.at(name).metrics();
    d.has_split = true;
  }
}

std::string SyntheticScoring::noGhostsReason() const {
  return std::filesystem::exists(truth_->movingBoxesPath()) ? ""
                                                              : "the dataset has no moving-object boxes (gt/moving_objects.txt)";
}

} // namespace msf
