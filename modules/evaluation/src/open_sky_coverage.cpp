// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/message_text.h>
#include <msf/evaluation/open_sky_coverage.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace msf {

OpenSkyCoverage::OpenSkyCoverage(const PinholeCamera& camera) : camera_(camera) {
  if (!camera.valid())
    throw InvalidInputError("protocol 6: invalid camera (" + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + " px, fx " + std::to_string(camera.fx) + ")");
}

void OpenSkyCoverage::addMask(std::size_t frame, const cv::Mat& mask) {
  if (mask.type() != CV_8UC1 || mask.cols != camera_.width || mask.rows != camera_.height)
    throw InvalidInputError("protocol 6: the sky mask of frame " + std::to_string(frame) + " is a " + sizeText(mask) +
                            " image of type " + std::to_string(mask.type()) + ", expected CV_8UC1 of the camera's " +
                            std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
  FrameSky sky;
  for (int v = 0; v < mask.rows; ++v) {
    const std::uint8_t* m = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < mask.cols;) {
      if (!m[u]) {
        ++u;
        continue;
      }
      const int start = u;
      while (u < mask.cols && m[u])
        ++u;
      sky.runs.push_back(static_cast<std::uint32_t>(v * mask.cols + start));
      sky.runs.push_back(static_cast<std::uint32_t>(u - start));
      sky.pixels += static_cast<std::size_t>(u - start);
    }
  }
  sky.runs.shrink_to_fit();
  const std::lock_guard<std::mutex> lock(mutex_);
  FrameSky& kept = frames_[frame];
  if (kept.has_mask)
    throw InvalidInputError("protocol 6: the sky mask of frame " + std::to_string(frame) + " is given twice");
  sky.has_mask = true;
  sky.has_pose = kept.has_pose;
  sky.T_world_cam = kept.T_world_cam;
  kept = std::move(sky);
}

void OpenSkyCoverage::setPose(std::size_t frame, const Eigen::Isometry3d& T_world_cam) {
  if (!T_world_cam.matrix().allFinite())
    throw InvalidInputError("protocol 6: the pose of frame " + std::to_string(frame) + " is not finite");
  const std::lock_guard<std::mutex> lock(mutex_);
  FrameSky& sky = frames_[frame];
  sky.T_world_cam = T_world_cam;
  sky.has_pose = true;
}

void OpenSkyCoverage::Tally::addFrame(std::size_t index, std::size_t sky_pixels, std::size_t covered) {
  const double share = static_cast<double>(covered) / static_cast<double>(sky_pixels);
  out_.frame_share[index] = share;
  out_.sky_pixels += sky_pixels;
  out_.covered_pixels += covered;
  share_sum_ += share;
  if (share > out_.worst_share || out_.frame_share.size() == 1) {
    out_.worst_share = share;
    out_.worst_frame = index;
  }
}

SkyCoverage OpenSkyCoverage::Tally::coverage() const {
  SkyCoverage out = out_;
  if (!covered_depth_.empty()) {
    std::vector<float> depth = covered_depth_;
    const auto middle = depth.begin() + static_cast<long>(depth.size() / 2);
    std::nth_element(depth.begin(), middle, depth.end());
    out.covered_depth_median_m = *middle;
  }
  if (out.sky_pixels > 0) {
    out.share = static_cast<double>(out.covered_pixels) / static_cast<double>(out.sky_pixels);
    out.mean_frame_share = share_sum_ / static_cast<double>(out.frame_share.size());
  }
  return out;
}

SkyCoverage OpenSkyCoverage::scoreMesh(const TriangleMesh& mesh, const SurfaceFilter& counts) {
  Tally tally;
  MeshViewScoring views;
  addViews(views, tally, counts);
  views.score(mesh);
  return tally.coverage();
}

void OpenSkyCoverage::addViews(MeshViewScoring& views, Tally& tally, const SurfaceFilter& counts) {
  std::map<std::size_t, Eigen::Isometry3d> poses;
  std::map<std::size_t, int> sky_rows; // down to the lowest sky pixel: what the sky's scoring reads
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [index, sky] : frames_) {
      if (!sky.has_pose || !sky.has_mask)
        continue;
      ++tally.out_.frames;
      if (sky.pixels == 0)
        continue; // a frame without sky counts, with nothing to render
      poses[index] = sky.T_world_cam;
      sky_rows[index] = static_cast<int>(sky.runs[sky.runs.size() - 2] / static_cast<std::uint32_t>(camera_.width)) + 1;
    }
  }
  const auto count = [this, &tally, counts](std::size_t index, const cv::Mat& rendered) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const FrameSky& sky = frames_.at(index);
    const float* depth = rendered.ptr<float>(0);
    const Eigen::Isometry3f T = sky.T_world_cam.cast<float>();
    const auto point = [&](std::uint32_t p) { // the surface point seen at pixel p, in the world
      const auto u = static_cast<float>(p % static_cast<std::uint32_t>(camera_.width));
      const auto v = static_cast<float>(p / static_cast<std::uint32_t>(camera_.width));
      return T * camera_.point(u, v, depth[p]);
    };
    std::size_t covered = 0;
    for (std::size_t r = 0; r < sky.runs.size(); r += 2)
      for (std::uint32_t p = sky.runs[r], end = p + sky.runs[r + 1]; p < end; ++p)
        if (depth[p] > 0.f && (!counts || counts(point(p)))) {
          ++covered;
          tally.covered_depth_.push_back(depth[p]);
        }
    tally.addFrame(index, sky.pixels, covered);
  };
  views.add(camera_, poses, count, sky_rows);
}

cv::Mat OpenSkyCoverage::drawCoverage(const cv::Mat& image, const cv::Mat& mask, const cv::Mat& rendered) {
  if (mask.size() != image.size() || rendered.size() != image.size() || mask.type() != CV_8UC1 ||
      rendered.type() != CV_32FC1)
    throw InvalidInputError("protocol 6: the picture needs a CV_8UC1 mask and a CV_32FC1 rendering of the image's " +
                            sizeText(image) + ", got " + sizeText(mask) + " and " + sizeText(rendered));
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else
    out = image.clone();
  for (int v = 0; v < out.rows; ++v) {
    const std::uint8_t* m = mask.ptr<std::uint8_t>(v);
    const float* z = rendered.ptr<float>(v);
    cv::Vec3b* p = out.ptr<cv::Vec3b>(v);
    for (int u = 0; u < out.cols; ++u)
      if (m[u]) // half the pixel, half cyan (sky: it shows on a deep blue sky too) or red (a surface over it)
        p[u] = p[u] / 2 + (z[u] > 0.f ? cv::Vec3b(0, 0, 127) : cv::Vec3b(127, 127, 0));
  }
  return out;
}

std::size_t OpenSkyCoverage::frames() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return frames_.size();
}

} // namespace msf
