// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// The real LiDAR returns of an interpolated depth image: `depth` where `distance` (pixels to
/// the nearest real return: LidarCompletion::computeDepth's second image, or the `distance`
/// field of PointXYZID) is 0, and 0 elsewhere. Guided stereo takes them as its hints
/// (SgbmStereo::setGuidance), so that the pipeline and msf_stereo -prior need no second
/// projection of the scan. Both images CV_32FC1 of one size.
cv::Mat realReturns(const cv::Mat& depth, const cv::Mat& distance);

} // namespace msf
