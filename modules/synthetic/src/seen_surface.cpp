// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/pinhole_camera.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/seen_surface.h>

#include <Eigen/Geometry>

namespace msf::synthetic {

void SeenSurface::add(const Sequence& sequence, const std::vector<std::size_t>& frames, double max_depth_m,
                      int stride) {
  if (stride < 1)
    throw InvalidInputError("the seen surface takes every n-th pixel with n >= 1, got " + std::to_string(stride));
  if (sequence.groundTruthDir().empty())
    throw IOError("sequence '" + sequence.directory() + "' has no synthetic ground truth (gt/)");
  if (!sequence.hasPoses())
    throw IOError("sequence '" + sequence.directory() + "' has no poses to place its ground truth with");
  const GroundTruth truth(sequence.groundTruthDir());
  const PinholeCamera camera = PinholeCamera::fromCalibration(sequence.calibration(), 0);
  const float far = static_cast<float>(max_depth_m);
  for (const std::size_t i : frames) {
    const std::size_t k = truth.indexOf(sequence.frameName(i));
    const cv::Mat depth = truth.depth(k), moving = truth.movingMask(k);
    const Eigen::Isometry3f T_world_cam0 = sequence.poses().at(i).cast<float>();
    for (int v = 0; v < depth.rows; v += stride)
      for (int u = 0; u < depth.cols; u += stride) {
        const float z = depth.at<float>(v, u);
        if (!(z > 0.f) || z > far || moving.at<std::uint8_t>(v, u) != 0)
          continue;
        points.push_back(T_world_cam0 * camera.point(static_cast<float>(u), static_cast<float>(v), z));
        depths.push_back(z);
      }
  }
}

} // namespace msf::synthetic
