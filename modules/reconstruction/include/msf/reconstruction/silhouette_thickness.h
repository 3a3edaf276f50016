// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// The widest hole (pixels without depth) between an object's end and the depth past it that
/// silhouetteThickness looks across.
constexpr int kSilhouetteMaxHole = 16;

/// Per pixel of a depth image, how thick the object it lies on can be seen to be (metres): the
/// width of its run along its row (or column) times its depth over the focal length, where the
/// run is bounded on both sides by a depth edge beyond which the image sees farther (across a
/// hole of at most kSilhouetteMaxHole pixels without depth). A pole 9 pixels wide at 12 m is
/// 0.15 m thick; a wall, the road or anything touching the image's border, a longer hole or
/// something nearer is not bounded (infinity). The lesser of the row's and the column's.
///
/// Two neighbours are on one object unless their depths differ by more than
/// max(relative_jump x the nearer depth, sigmas x the larger of their sigmas), sigma =
/// 1 / sqrt(weight): noise in far stereo does not cut a wall into slivers.
///
/// depth, weight: CV_32FC1 of one size (weight in m^-2; not > 0 = none). Writes `thickness`
/// (CV_32FC1), reusing its buffer. Rows and columns run in parallel. Throws InvalidInputError
/// for other types or sizes, a camera without focal lengths or negative thresholds.
void silhouetteThickness(const cv::Mat& depth, const cv::Mat& weight, const PinholeCamera& camera,
                         float relative_jump, float sigmas, cv::Mat& thickness);

} // namespace msf
