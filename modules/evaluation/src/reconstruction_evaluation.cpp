// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/reconstruction_evaluation.h>

#include <cmath>

namespace msf {

namespace {
constexpr std::uint32_t kMoving = 1u << 31;
enum Set { kStatic = 0, kStaticInRange = 1, kMovingAll = 2, kMovingInRange = 3 };
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

void ReconstructionEvaluation::setNearPlane(float near_m) {
  const std::lock_guard<std::mutex> lock(mutex_);
  rasterizer_.setNearPlane(near_m);
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
  if (!frames_.emplace(frame, std::move(truth)).second)
    throw InvalidInputError("protocol 4: " + name + " was given twice");
}

ReconstructionEvaluation::Row& ReconstructionEvaluation::row(const std::string& source) {
  for (Row& r : rows_)
    if (r.source == source)
      return r;
  rows_.push_back(Row{source, {}});
  return rows_.back();
}

void ReconstructionEvaluation::score(Row& row, const FrameTruth& truth, const cv::Mat& depth) const {
  const auto width = static_cast<std::uint32_t>(camera_.width);
  for (std::size_t k = 0; k < truth.pixels.size(); ++k) {
    const std::uint32_t pixel = truth.pixels[k] & ~kMoving;
    const float gt = truth.depth[k];
    const float estimate = depth.ptr<float>(static_cast<int>(pixel / width))[pixel % width];
    const int set = truth.pixels[k] & kMoving ? kMovingAll : kStatic;
    row.errors[set].addPixel(gt, estimate, focal_baseline_, d1_);
    if (gt <= max_depth_m_)
      row.errors[set + 1].addPixel(gt, estimate, focal_baseline_, d1_);
  }
}

void ReconstructionEvaluation::scoreDepth(const std::string& source, std::size_t frame, const cv::Mat& depth) {
  checkImage(depth, CV_32FC1, source + " depth of frame " + std::to_string(frame));
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto truth = frames_.find(frame);
  if (truth == frames_.end())
    throw InvalidInputError("protocol 4: frame " + std::to_string(frame) + " has no ground truth to score its " +
                            source + " depth against");
  score(row(source), truth->second, depth);
}

void ReconstructionEvaluation::scoreMesh(const std::string& source, const TriangleMesh& mesh) {
  const std::lock_guard<std::mutex> lock(mutex_);
  Row& r = row(source);
  for (const auto& [frame, truth] : frames_) {
    rasterizer_.render(mesh, camera_, truth.T_world_cam, rendered_);
    score(r, truth, rendered_);
  }
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
  for (const Row& r : rows_)
    out.push_back({r.source, r.errors[kStatic].metrics(), r.errors[kStaticInRange].metrics(),
                   r.errors[kMovingAll].metrics(), r.errors[kMovingInRange].metrics()});
  return out;
}

} // namespace msf
