// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/reconstruction_evaluation.h>
#include <msf/reconstruction/mesh_components.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace msf {

namespace {
constexpr std::uint32_t kMoving = 1u << 31, kTransient = 1u << 30, kPixel = kTransient - 1;
enum Set { kStatic, kStaticInRange, kMovingAll, kMovingInRange, kLastingInRange, kTransientInRange, kSets };
} // namespace

ReconstructionEvaluation::ReconstructionEvaluation(const PinholeCamera& camera, double focal_baseline,
                                                   double max_depth_m, const D1Threshold& d1)
    : camera_(camera), focal_baseline_(focal_baseline), max_depth_m_(max_depth_m), d1_(d1) {
  if (!camera.valid())
    throw InvalidInputError("protocol 4: invalid camera (" + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + " px, fx " + std::to_string(camera.fx) + ")");
  if (!(focal_baseline > 0.0) || !std::isfinite(focal_baseline))
    throw InvalidInputError("protocol 4: focal length x baseline must be > 0, not " + std::to_string(focal_baseline));
  if (!(max_depth_m > 0.0))
    throw ConfigError("protocol 4: the reconstruction's depth range must be > 0 m, not " + std::to_string(max_depth_m));
}

void ReconstructionEvaluation::checkImage(const cv::Mat& image, int type, const std::string& what) const {
  if (image.type() != type || image.cols != camera_.width || image.rows != camera_.height)
    throw InvalidInputError("protocol 4: " + what + " is a " + std::to_string(image.cols) + "x" +
                            std::to_string(image.rows) + " image of type " + std::to_string(image.type()) +
                            ", expected type " + std::to_string(type) + " of the camera's " +
                            std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
}

void ReconstructionEvaluation::addGroundTruth(std::size_t frame, const Eigen::Isometry3d& T_world_cam,
                                              const cv::Mat& depth, const cv::Mat& moving) {
  const std::string name = "ground truth of frame " + std::to_string(frame);
  checkImage(depth, CV_32FC1, name);
  if (!moving.empty())
    checkImage(moving, CV_8UC1, "moving mask of frame " + std::to_string(frame));
  if (!T_world_cam.matrix().allFinite())
    throw InvalidInputError("protocol 4: the pose of frame " + std::to_string(frame) + " is not finite");
  FrameTruth truth;
  truth.T_world_cam = T_world_cam;
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    const std::uint8_t* m = moving.empty() ? nullptr : moving.ptr<std::uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u)
      if (std::isfinite(z[u]) && z[u] > 0.f) {
        truth.pixels.push_back(static_cast<std::uint32_t>(v * depth.cols + u) | (m && m[u] ? kMoving : 0u));
        truth.depth.push_back(z[u]);
      }
  }
  truth.pixels.shrink_to_fit();
  truth.depth.shrink_to_fit();
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto [added, fresh] = frames_.emplace(frame, std::move(truth));
  if (!fresh)
    throw InvalidInputError("protocol 4: " + name + " was given twice");
  for (const auto& [index, scan] : scans_)
    if (index != frame && std::max(index, frame) - std::min(index, frame) <= kScanWindow)
      markTransient(added->second, scan);
}

void ReconstructionEvaluation::addScan(std::size_t frame, const Eigen::Isometry3d& T_world_lidar,
                                       const ScanFreeSpace& free_space) {
  if (!T_world_lidar.matrix().allFinite())
    throw InvalidInputError("protocol 4: the LiDAR pose of frame " + std::to_string(frame) + " is not finite");
  if (free_space.empty())
    return;
  const std::lock_guard<std::mutex> lock(mutex_);
  splits_transient_ = true;
  const Scan scan{T_world_lidar.inverse(), free_space};
  for (auto truth = frames_.lower_bound(frame > kScanWindow ? frame - kScanWindow : 0);
       truth != frames_.end() && truth->first <= frame + kScanWindow; ++truth)
    if (truth->first != frame)
      markTransient(truth->second, scan);
  scans_[frame] = scan;
  while (scans_.begin()->first + kScanWindow < frame)
    scans_.erase(scans_.begin());
  last_scan_ = std::max(last_scan_, frame);
  scoreSettledFrames();
}

bool ReconstructionEvaluation::splitsTransient() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return splits_transient_;
}

void ReconstructionEvaluation::markTransient(FrameTruth& truth, const Scan& scan) const {
  const Eigen::Isometry3f T_lidar_cam = (scan.T_lidar_world * truth.T_world_cam).cast<float>();
  const auto width = static_cast<std::uint32_t>(camera_.width);
  for (std::size_t k = 0; k < truth.pixels.size(); ++k) {
    const std::uint32_t pixel = truth.pixels[k] & kPixel;
    const Eigen::Vector3f p_cam = camera_.point(static_cast<float>(pixel % width), static_cast<float>(pixel / width),
                                                truth.depth[k]);
    const Eigen::Vector3f p = T_lidar_cam * p_cam;
    const double behind = scan.free_space.nearestAround(p) - scan.free_space.skew();
    const double range = p.norm();
    // Seen from the scan as protocol 4 sees depth: its returns lie a D1 outlier behind this one.
    if (behind > range && d1_.exceeded(focal_baseline_ / range - focal_baseline_ / behind, focal_baseline_ / behind))
      truth.pixels[k] |= kTransient;
  }
}

ReconstructionEvaluation::Row& ReconstructionEvaluation::row(const std::string& source) {
  for (Row& r : rows_)
    if (r.source == source)
      return r;
  rows_.push_back(Row{source, std::vector<DepthErrorAccumulator>(kSets), {}});
  return rows_.back();
}

std::vector<float> ReconstructionEvaluation::sample(const FrameTruth& truth, const cv::Mat& depth) const {
  const auto width = static_cast<std::uint32_t>(camera_.width);
  std::vector<float> estimates(truth.pixels.size());
  for (std::size_t k = 0; k < truth.pixels.size(); ++k) {
    const std::uint32_t pixel = truth.pixels[k] & kPixel;
    estimates[k] = depth.ptr<float>(static_cast<int>(pixel / width))[pixel % width];
  }
  return estimates;
}

void ReconstructionEvaluation::accumulate(std::vector<DepthErrorAccumulator>& errors, const FrameTruth& truth,
                                          const std::vector<float>& estimates) const {
  for (std::size_t k = 0; k < truth.pixels.size(); ++k) {
    const float gt = truth.depth[k], estimate = estimates[k];
    const bool moving = truth.pixels[k] & kMoving, in_range = gt <= max_depth_m_;
    const int set = moving ? kMovingAll : kStatic;
    errors[set].addPixel(gt, estimate, focal_baseline_, d1_);
    if (in_range)
      errors[set + 1].addPixel(gt, estimate, focal_baseline_, d1_);
    if (in_range && !moving)
      errors[truth.pixels[k] & kTransient ? kTransientInRange : kLastingInRange].addPixel(gt, estimate,
                                                                                          focal_baseline_, d1_);
  }
}

void ReconstructionEvaluation::score(Row& row, std::size_t frame, const FrameTruth& truth, const cv::Mat& depth) {
  std::vector<float> estimates = sample(truth, depth);
  if (splits_transient_ && last_scan_ < frame + kScanWindow)
    row.waiting[frame] = std::move(estimates);
  else
    accumulate(row.errors, truth, estimates);
}

void ReconstructionEvaluation::scoreSettledFrames() {
  for (Row& r : rows_)
    while (!r.waiting.empty() && r.waiting.begin()->first + kScanWindow <= last_scan_) {
      accumulate(r.errors, frames_.at(r.waiting.begin()->first), r.waiting.begin()->second);
      r.waiting.erase(r.waiting.begin());
    }
}

void ReconstructionEvaluation::scoreDepth(const std::string& source, std::size_t frame, const cv::Mat& depth) {
  checkImage(depth, CV_32FC1, source + " depth of frame " + std::to_string(frame));
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto truth = frames_.find(frame);
  if (truth == frames_.end())
    throw InvalidInputError("protocol 4: frame " + std::to_string(frame) + " has no ground truth to score its " +
                            source + " depth against");
  score(row(source), frame, truth->second, depth);
}

void ReconstructionEvaluation::scoreMesh(const std::string& source, const TriangleMesh& mesh) {
  MeshViewScoring views;
  addViews(views, source);
  views.score(mesh);
}

void ReconstructionEvaluation::addViews(MeshViewScoring& views, const std::string& source) {
  std::map<std::size_t, Eigen::Isometry3d> poses;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    row(source); // the row's place among the sources: where it is asked, as scoreDepth's
    for (const auto& [frame, truth] : frames_)
      poses[frame] = truth.T_world_cam;
  }
  views.add(camera_, poses,
            [this, source](std::size_t frame, const cv::Mat& rendered) { scoreDepth(source, frame, rendered); });
}

SeenThroughPieces ReconstructionEvaluation::seenThroughPieces(const TriangleMesh& mesh,
                                                              std::size_t max_triangles) const {
  if (max_triangles == 0)
    throw InvalidInputError("protocol 4: a small piece must be allowed at least one triangle");
  SeenThroughPieces out;
  out.max_triangles = max_triangles;
  const std::vector<std::uint32_t> piece = componentLabels(mesh);
  std::unordered_map<std::uint32_t, std::size_t> triangles;
  for (const auto& t : mesh.triangles)
    ++triangles[piece[t[0]]];
  out.pieces = triangles.size();
  std::vector<std::uint32_t> small_vertices;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto it = triangles.find(piece[v]);
    if (it != triangles.end() && it->second < max_triangles)
      small_vertices.push_back(static_cast<std::uint32_t>(v));
  }

  // Per small vertex: 1 met ground truth, 2 was seen through.
  std::vector<std::uint8_t> state(small_vertices.size(), 0);
  const std::lock_guard<std::mutex> lock(mutex_);
  cv::Mat truth_depth(camera_.height, camera_.width, CV_32FC1);
  const auto width = static_cast<std::uint32_t>(camera_.width);
  for (const auto& [frame, truth] : frames_) {
    truth_depth.setTo(0.f);
    for (std::size_t k = 0; k < truth.pixels.size(); ++k) {
      const std::uint32_t pixel = truth.pixels[k] & kPixel;
      truth_depth.at<float>(static_cast<int>(pixel / width), static_cast<int>(pixel % width)) = truth.depth[k];
    }
    const Eigen::Isometry3f T_cam_world = truth.T_world_cam.inverse().cast<float>();
    for (std::size_t i = 0; i < small_vertices.size(); ++i)
      state[i] = std::max(state[i], seenThrough(T_cam_world * mesh.vertices[small_vertices[i]], truth_depth));
  }

  std::unordered_map<std::uint32_t, std::pair<std::size_t, std::size_t>> met_seen; // per small piece
  for (std::size_t i = 0; i < small_vertices.size(); ++i) {
    auto& [met, seen] = met_seen[piece[small_vertices[i]]];
    met += state[i] > 0;
    seen += state[i] > 1;
  }
  for (const auto& [label, count] : triangles)
    if (count < max_triangles) {
      ++out.small_pieces;
      const auto& [met, seen] = met_seen[label];
      if (2 * seen > met) {
        ++out.seen_through;
        out.triangles += count;
      }
    }
  return out;
}

std::uint8_t ReconstructionEvaluation::seenThrough(const Eigen::Vector3f& p_cam, const cv::Mat& truth_depth) const {
  if (!(p_cam.z() > 0.f))
    return 0;
  const int u = static_cast<int>(std::lround(camera_.fx * p_cam.x() / p_cam.z() + camera_.cx));
  const int v = static_cast<int>(std::lround(camera_.fy * p_cam.y() / p_cam.z() + camera_.cy));
  if (u < 1 || v < 1 || u >= camera_.width - 1 || v >= camera_.height - 1)
    return 0;
  const double vertex_disparity = focal_baseline_ / p_cam.z();
  bool met = false;
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) {
      const float z = truth_depth.at<float>(v + dv, u + du);
      if (!(z > 0.f))
        continue;
      met = true;
      const double true_disparity = focal_baseline_ / z;
      const double in_front = vertex_disparity - true_disparity; // > 0: the vertex is nearer
      if (!d1_.exceeded(in_front, true_disparity))
        return 1;
    }
  return met ? 2 : 0;
}

std::size_t ReconstructionEvaluation::frames() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return frames_.size();
}

std::size_t ReconstructionEvaluation::groundTruthPixels() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::size_t n = 0;
  for (const auto& f : frames_)
    n += f.second.pixels.size();
  return n;
}

std::vector<ReconstructionScore> ReconstructionEvaluation::scores() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ReconstructionScore> out;
  for (const Row& r : rows_) {
    std::vector<DepthErrorAccumulator> errors = r.errors;
    for (const auto& [frame, estimates] : r.waiting)
      accumulate(errors, frames_.at(frame), estimates);
    out.push_back({r.source, errors[kStatic].metrics(), errors[kStaticInRange].metrics(),
                   errors[kMovingAll].metrics(), errors[kMovingInRange].metrics(), errors[kLastingInRange].metrics(),
                   errors[kTransientInRange].metrics()});
  }
  return out;
}

} // namespace msf
