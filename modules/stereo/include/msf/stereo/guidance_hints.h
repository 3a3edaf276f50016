// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// The hints that guide SemiGlobalMatcher::compute from a sparse depth (the projected LiDAR
/// returns, CV_32FC1 metres, 0 or NaN = none): disparity x 16 (CV_16SC1, f B / z rounded)
/// at each return, 0 elsewhere.
///
/// Bridging: in each column, the rows between two consecutive returns at most `bridge_rows`
/// apart whose disparities differ by at most `bridge_agreement` of the larger get hints
/// linear in the row between the two (a plane's disparity is affine in the pixel), so that
/// the rows between two LiDAR rings are guided too; 3-way SGM's paths alone carry a hint
/// only down the column, and by at most P2 a pixel. Returns that disagree (a depth edge
/// between the rings) leave their rows to the image. 0 rows: the returns only.
/// Throws InvalidInputError for a depth that is not CV_32FC1, focal_baseline <= 0, or a
/// negative bridge.
cv::Mat guidanceHints(const cv::Mat& sparse_depth, double focal_baseline, int bridge_rows = 0,
                      float bridge_agreement = 0.f);

/// The hints of the right view for its match as the left view of the mirrored pair (the
/// explicit left-right check): each hint moves to column u - d, the nearer winning where two
/// land on one pixel, and the image is mirrored. Throws InvalidInputError for a type other
/// than CV_16SC1.
cv::Mat rightViewHintsMirrored(const cv::Mat& hints);

} // namespace msf
