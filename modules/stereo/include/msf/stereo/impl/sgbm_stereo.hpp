// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/stereo/color_sampler.h>
#include <msf/stereo/point_field_traits.h>
#include <msf/stereo/sgbm_stereo.h>

#include <opencv2/core/utility.hpp>

#include <atomic>
#include <cmath>
#include <limits>

namespace msf {

template <typename PointT>
void SgbmStereo::compute(pcl::PointCloud<PointT>& output) {
  if (!has_calibration_)
    throw CalibrationError("SgbmStereo: no calibration set (setCalibration)");
  computeDisparity();
  const int rows = disparity_.rows, cols = disparity_.cols;
  const float fB = static_cast<float>(calibration_.focalBaseline());
  const float fx = static_cast<float>(calibration_.fx(0)), fy = static_cast<float>(calibration_.fy(0));
  const float cx = static_cast<float>(calibration_.cx(0)), cy = static_cast<float>(calibration_.cy(0));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Colour from the colour camera by projection; the left grey pixel where it projects
  // outside, or when no colour image was given.
  const ColorSampler sampler = color_.empty() ? ColorSampler() : ColorSampler(color_, calibration_, config_.color_camera);
  output.resize(static_cast<std::size_t>(rows) * cols);
  output.width = static_cast<std::uint32_t>(cols);
  output.header.frame_id = cameraFrameId(0); // the disparity of the left grey camera
  output.height = static_cast<std::uint32_t>(rows);
  // cv::parallel_for_ (work stealing) keeps both cores busy on a shared machine.
  std::atomic<bool> dense{true};
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    bool range_dense = true;
    for (int v = range.start; v < range.end; ++v) {
      const float* d = disparity_.ptr<float>(v);
      const float* c = confidence_.ptr<float>(v);
      const std::uint8_t* grey = left_.ptr<std::uint8_t>(v);
      PointT* out = &output[static_cast<std::size_t>(v) * cols];
      for (int u = 0; u < cols; ++u) {
        PointT& p = out[u];
        if (d[u] > 0.f) {
          const float z = fB / d[u];
          p.x = (static_cast<float>(u) - cx) * z / fx;
          p.y = (static_cast<float>(v) - cy) * z / fy;
          p.z = z;
        } else {
          p.x = p.y = p.z = nan;
          range_dense = false;
        }
        if constexpr (detail::has_rgb_v<PointT>) {
          std::uint8_t r, g, b;
          if (left_.channels() == 3) {
            b = grey[3 * u];
            g = grey[3 * u + 1];
            r = grey[3 * u + 2];
          } else {
            r = g = b = grey[u];
          }
          if (d[u] > 0.f)
            sampler.sample(p.x, p.y, p.z, r, g, b);
          p.r = r;
          p.g = g;
          p.b = b;
          p.a = 255;
        }
        if constexpr (detail::has_confidence_v<PointT>)
          p.confidence = c[u];
      }
    }
    if (!range_dense)
      dense = false;
  });
  output.is_dense = dense;
}

} // namespace msf
