// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/io/image_io.h>
#include <msf/synthetic/ground_truth.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>

namespace fs = std::filesystem;

namespace msf::synthetic {

namespace {
bool isGroundTruthDir(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p / "depth_0", ec);
}
} // namespace

std::string GroundTruth::find(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec).lexically_normal();
  if (ec || !fs::is_directory(p, ec))
    return "";
  if (p.filename().empty())
    p = p.parent_path();
  // The folder itself, a dataset root, or a sequence two levels below the root.
  for (const fs::path& candidate : {p, p / "gt", p.parent_path().parent_path() / "gt"})
    if (isGroundTruthDir(candidate))
      return candidate.string();
  return "";
}

GroundTruth::GroundTruth(const std::string& path) {
  dir_ = find(path);
  if (dir_.empty())
    throw IOError("'" + path +
                  "' has no synthetic ground truth (gt/depth_0/ in it, in its gt/, or in the dataset root above "
                  "a sequences/XX folder)");
  for (const auto& e : fs::directory_iterator(fs::path(dir_) / "depth_0"))
    if (e.is_regular_file() && e.path().extension() == ".png")
      names_.push_back(e.path().stem().string());
  std::sort(names_.begin(), names_.end());
  if (names_.empty())
    throw IOError("ground truth '" + dir_ + "' has no depth_0/*.png");
}

const std::string& GroundTruth::frameName(std::size_t i) const {
  if (i >= names_.size())
    throw InvalidInputError("ground-truth frame " + std::to_string(i) + " is out of range: '" + dir_ + "' has " +
                            std::to_string(names_.size()) + " frames");
  return names_[i];
}

std::size_t GroundTruth::indexOf(const std::string& frame_name) const {
  const auto it = std::lower_bound(names_.begin(), names_.end(), frame_name);
  if (it == names_.end() || *it != frame_name)
    throw InvalidInputError("ground truth '" + dir_ + "' has no frame '" + frame_name + "'");
  return static_cast<std::size_t>(it - names_.begin());
}

std::string GroundTruth::depthPath(std::size_t i) const {
  return (fs::path(dir_) / "depth_0" / (frameName(i) + ".png")).string();
}
std::string GroundTruth::disparityPath(std::size_t i) const {
  return (fs::path(dir_) / "disp_0" / (frameName(i) + ".png")).string();
}
std::string GroundTruth::objectMapPath(std::size_t i) const {
  return (fs::path(dir_) / "obj_map_0" / (frameName(i) + ".png")).string();
}
std::string GroundTruth::movingMaskPath(std::size_t i) const {
  return (fs::path(dir_) / "moving_0" / (frameName(i) + ".png")).string();
}
std::string GroundTruth::movingBoxesPath() const { return (fs::path(dir_) / "moving_objects.txt").string(); }
std::string GroundTruth::sceneMeshPath() const {
  const std::string path = (fs::path(dir_) / "scene.ply").string();
  requireFile(path, "scene mesh");
  return path;
}

std::string GroundTruth::sceneClassesPath() const { return (fs::path(dir_) / "scene_classes.txt").string(); }

bool GroundTruth::hasSceneClasses() const {
  std::error_code ec;
  return fs::is_regular_file(sceneClassesPath(), ec);
}

SurfaceClasses GroundTruth::sceneClasses(std::size_t vertices) const {
  return readSurfaceClasses(sceneClassesPath(), vertices);
}

bool GroundTruth::hasMovingMasks() const {
  std::error_code ec;
  return fs::is_directory(fs::path(dir_) / "moving_0", ec);
}

cv::Mat GroundTruth::depth(std::size_t i) const { return readKittiDepthPng(depthPath(i)); }
cv::Mat GroundTruth::disparity(std::size_t i) const { return readKittiDisparityPng(disparityPath(i)); }

namespace {
cv::Mat readByteImage(const std::string& path, const char* what) {
  const cv::Mat image = readImage(path, cv::IMREAD_UNCHANGED);
  if (image.type() != CV_8UC1)
    throw IOError(std::string(what) + " '" + path + "' is not an 8-bit single-channel PNG");
  return image;
}
} // namespace

cv::Mat GroundTruth::objectMap(std::size_t i) const { return readByteImage(objectMapPath(i), "object map"); }

std::vector<MovingBox> GroundTruth::movingBoxes() const { return readMovingBoxes(movingBoxesPath()); }

GroundTruth::Split GroundTruth::split(std::size_t i, const cv::Mat& depth) const {
  const cv::Mat valid = (depth.empty() ? this->depth(i) : depth) > 0.f, objects = objectMap(i);
  if (valid.size() != objects.size())
    throw IOError("object map '" + objectMapPath(i) + "' and depth '" + depthPath(i) + "' differ in size");
  return {valid & (objects == 0), valid & (objects > 0)};
}

cv::Mat GroundTruth::movingMask(std::size_t i) const {
  const cv::Mat truth = depth(i);
  if (!hasMovingMasks())
    return cv::Mat::zeros(truth.size(), CV_8UC1);
  const std::string path = movingMaskPath(i);
  requireFile(path, "moving-object mask");
  const cv::Mat mask = readImage(path, cv::IMREAD_UNCHANGED);
  if (mask.type() != CV_8UC1 || mask.size() != truth.size())
    throw IOError("moving-object mask '" + path + "' is not an 8-bit single-channel PNG of the depth's size " +
                  std::to_string(truth.cols) + "x" + std::to_string(truth.rows));
  return mask;
}

} // namespace msf::synthetic
