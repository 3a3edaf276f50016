// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/fusion/fusion_config.h>
#include <msf/io/calibration.h>
#include <msf/io/pinhole_camera.h>

#include <opencv2/core/mat.hpp>

#include <cstddef>

namespace msf {

/// After the fusion (fusion.facade_extension): a wall the LiDAR saw up to its top ring goes on
/// above it, where the image still shows the same blank surface. A blank wall gives stereo no
/// texture to match, so above the LiDAR's reach it has no depth, or SGBM's guesses; this
/// continues each column's LiDAR-backed surface upward instead.
///
/// Each column is walked from the bottom up. Its anchors are fused pixels known to within
/// facade_anchor_sigma_m (LiDAR-backed, or stereo near the cameras); the last run of them is
/// fitted with a line in inverse depth against the row, its nearest rows weighing most. Above
/// the run the wall goes on vertical, at the run's inverse depth (on a vertical plane a level
/// camera sees 1/z constant up a column; an anchor it reaches joins the run), while
/// - the surface is near vertical: the line's slope gives the normal's component along the
///   image's y axis at most facade_max_normal_y (a wall, not the road or a car's roof, whose
///   line leads into the sky);
/// - the image looks the same and blank: the grey's mean over 5x5 pixels stays within
///   facade_grey_tolerance of the run's, and its standard deviation there within
///   facade_max_texture (about twice the image noise: the wall's top edge against the sky,
///   another object or a texture stereo can match stops it), and not overexposed (a mean of 250
///   or more: a bright sky is blank too). Other image up to facade_max_gap_m high (a window) is
///   crossed if the wall's grey comes back above it and stereo there sees the wall: some of its
///   pixels agree with the wall within 3 sigmas, none disagrees (a pole, a tree's crown, a
///   building behind a roof's edge stop the column). Its pixels then take the wall too, their
///   sigma with 0.1 m added for a window's recess;
/// - stereo does not see the surface behind it: three of the column's pixels with a depth in a
///   row, each more than 6 of its own sigmas behind the wall, stop the column (the wall's top
///   edge against a building behind it of the same grey); the third and those above keep their
///   depth.
/// A pixel on the way takes the wall's depth with the sigma of the run's last anchor plus
/// facade_sigma_per_m per metre above it (a wall leaning by ~3 degrees, or a camera pitched so),
/// as its weight and free space weight (1 / sigma^2). A depth of its own that agrees within 3
/// sigmas (its own or the wall's) is averaged with the wall's by inverse variance, the weights
/// added; other stereo on a blank surface is a guess, and is replaced.
///
/// left: CV_8UC1, the grey image of camera 0 (the fused depth's pixels); depth, weight (and
/// free_space_weight, if not empty): CV_32FC1 of its size, changed in place. Columns run in
/// parallel. Returns the number of pixels given a depth. Throws InvalidInputError for images of
/// another type or size, or an invalid camera.
std::size_t extendFacades(const cv::Mat& left, const PinholeCamera& camera, const DepthFusionConfig& config,
                          cv::Mat& depth, cv::Mat& weight, cv::Mat& free_space_weight);

/// The same through camera 0 of `calibration`, at the depth image's size (the fusion's form:
/// DepthImageFusion and DepthFusion run it when given the grey image, setInputImage).
std::size_t extendFacades(const cv::Mat& left, const Calibration& calibration, const DepthFusionConfig& config,
                          cv::Mat& depth, cv::Mat& weight, cv::Mat& free_space_weight);

} // namespace msf
