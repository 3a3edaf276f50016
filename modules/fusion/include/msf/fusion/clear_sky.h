// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/sky_mask.h>

#include <opencv2/core/mat.hpp>

namespace msf {

/// No depth in the clear sky (fusion.clear_sky): SGBM's paths carry a crown's disparity over the
/// blank sky beside it and the interpolation carries the LiDAR there, and the map would hang
/// them as sheets. Finds the open sky of `image` (CV_8UC1 grey or CV_8UC3 BGR of camera 0's
/// view) above the LiDAR's real returns `returns` (CV_32FC1, > 0 at a return), and empties
/// `depth`, `weight` and `free_weight` (those not empty, CV_32FC1 of the image's size) at its
/// clear pixels (SkyMask::clearSky) up to where the image's texture starts
/// (SkyMask::computeWithoutBorder): SGBM widens a thin pole or a crown's rim by a few pixels of
/// blank sky, which the mask's border would leave. A colour camera beside camera 0 sees a near
/// pole shifted by their parallax: given `grey` (CV_8UC1, camera 0's own image; empty, or
/// `image` itself: none), camera 0's own open sky decides within the mask's border, and its
/// clipped pixels are withheld too, the sky camera 0 sees beside the pole where the colour
/// camera sees the pole, and the clipped ones beside an edge that its texture kept out of its
/// mask (SkyMask::clippedOutline): a clipped pixel has no texture of its own, and camera 0
/// sees the depth's pixels without parallax. A grey-white sky looks like a blank wall, so there
/// the depth is withheld only in front of the wall its column's returns allow
/// (SkyMask::wallDepth, by more than three of the pixel's sigmas, from `weight`), up to where
/// either camera's texture starts: stereo's paths carry a pole's depth over a pale sky beside it
/// too. Returns the open sky's
/// mask (SkyMask::compute of `image`) with every pixel withheld in it, so that no hole fill gives
/// them depth again. `clear_sky`, when given, receives the mask's clear pixels (CV_8UC1, 255;
/// in camera 0's own open sky too, given `grey`): rays that nothing but the sky stopped, which
/// the map may carve past the returns (TsdfIntegrator::carveSky). Throws InvalidInputError,
/// changing nothing, for a depth, weight or grey image of another type or size.
cv::Mat withholdClearSky(const SkyMask& sky, const cv::Mat& image, const cv::Mat& grey, const cv::Mat& returns,
                         cv::Mat& depth, cv::Mat& weight, cv::Mat& free_weight, cv::Mat* clear_sky = nullptr);

/// The image to find camera 0's open sky in: the colour camera's (BGR) when it has camera 0's
/// `size` (rectified, one image plane: it sees the far sky at camera 0's pixels, and colour tells
/// a blue sky from a white wall), else camera 0's grey one.
const cv::Mat& skyImage(const cv::Mat& colour, const cv::Mat& grey, const cv::Size& size);

} // namespace msf
