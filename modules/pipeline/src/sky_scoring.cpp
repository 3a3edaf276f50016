// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/image_io.h>
#include <msf/pipeline/sky_scoring.h>

#include <filesystem>

namespace msf {

SkyScoring::SkyScoring(const Calibration& calibration, const ProjectionConfig& projection,
                       std::set<std::size_t> picture_frames)
    : camera_(PinholeCamera::fromCalibration(calibration, projection.camera)), projector_(calibration, projection),
      coverage_(camera_), picture_frames_(std::move(picture_frames)) {}

const cv::Mat& SkyScoring::imageOf(const Frame& frame) const {
  // The colour camera's pixel sees the same far sky as camera 0's (rectified, one image
  // plane), so its colour is used where it has camera 0's size.
  const bool colour = !frame.color.empty() && frame.color.cols == camera_.width && frame.color.rows == camera_.height;
  return colour ? frame.color : frame.left;
}

cv::Mat SkyScoring::maskOf(const Frame& frame) {
  projector_.projectToImage(*frame.scan, returns_);
  return mask_.compute(imageOf(frame), returns_);
}

void SkyScoring::addFrame(const Frame& frame) {
  const cv::Mat mask = maskOf(frame);
  coverage_.addMask(frame.index, mask);
  if (picture_frames_.count(frame.index)) {
    const std::lock_guard<std::mutex> lock(mutex_);
    pictures_[frame.index] = {imageOf(frame).clone(), mask};
  }
}

std::map<std::string, SkyCoverage> SkyScoring::score(const std::map<std::string, const TriangleMesh*>& meshes) {
  std::map<std::string, SkyCoverage> out;
  for (const auto& [name, mesh] : meshes) {
    MeshViewScoring views;
    addViews(views, name);
    views.score(*mesh);
    out[name] = tallies_.at(name).coverage();
  }
  return out;
}

void SkyScoring::addViews(MeshViewScoring& views, const std::string& name) {
  OpenSkyCoverage::Tally& tally = tallies_[name];
  tally = OpenSkyCoverage::Tally();
  coverage_.addViews(views, tally);
}

std::map<std::string, SkyCoverage> SkyScoring::scores() const {
  std::map<std::string, SkyCoverage> out;
  for (const auto& [name, tally] : tallies_)
    out[name] = tally.coverage();
  return out;
}

std::vector<std::string> SkyScoring::drawPictures(const std::string& dir, const TriangleMesh& mesh,
                                                  const std::map<std::size_t, Eigen::Isometry3d>& poses,
                                                  const std::map<std::size_t, std::string>& names) {
  std::vector<std::string> written;
  MeshRasterizer rasterizer;
  cv::Mat rendered;
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [index, picture] : pictures_) {
    const auto pose = poses.find(index);
    if (pose == poses.end())
      continue;
    rasterizer.render(mesh, camera_, pose->second, rendered);
    const std::string name = "sky_" + names.at(index) + ".png";
    writeImage((std::filesystem::path(dir) / name).string(), OpenSkyCoverage::drawCoverage(picture.image, picture.mask, rendered));
    written.push_back(name);
  }
  return written;
}

} // namespace msf
