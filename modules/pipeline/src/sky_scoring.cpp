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
    Picture& picture = pictures_[frame.index]; // its pose may have come first
    picture.image = imageOf(frame).clone();
    picture.mask = mask;
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

void SkyScoring::setPose(std::size_t frame, const Eigen::Isometry3d& T_world_cam) {
  coverage_.setPose(frame, T_world_cam);
  if (!picture_frames_.count(frame))
    return;
  const std::lock_guard<std::mutex> lock(mutex_);
  Picture& picture = pictures_[frame];
  picture.T_world_cam = T_world_cam;
  picture.has_pose = true;
}

void SkyScoring::addViews(MeshViewScoring& views, const std::string& name, bool with_pictures) {
  OpenSkyCoverage::Tally& tally = tallies_[name];
  tally = OpenSkyCoverage::Tally();
  coverage_.addViews(views, tally);
  if (!with_pictures)
    return;
  std::map<std::size_t, Eigen::Isometry3d> poses;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [index, picture] : pictures_) {
      picture.rendered.release();
      if (picture.has_pose && !picture.image.empty())
        poses[index] = picture.T_world_cam;
    }
  }
  views.add(camera_, poses, [this](std::size_t frame, const cv::Mat& rendered) {
    const std::lock_guard<std::mutex> lock(mutex_);
    pictures_[frame].rendered = rendered.clone();
  });
}

std::map<std::string, SkyCoverage> SkyScoring::scores() const {
  std::map<std::string, SkyCoverage> out;
  for (const auto& [name, tally] : tallies_)
    out[name] = tally.coverage();
  return out;
}

std::vector<std::string> SkyScoring::drawPictures(const std::string& dir,
                                                  const std::map<std::size_t, std::string>& names) {
  std::vector<std::string> written;
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [index, picture] : pictures_) {
    if (picture.rendered.empty())
      continue;
    const std::string name = "sky_" + names.at(index) + ".png";
    writeImage((std::filesystem::path(dir) / name).string(),
               OpenSkyCoverage::drawCoverage(picture.image, picture.mask, picture.rendered));
    written.push_back(name);
  }
  return written;
}

} // namespace msf
