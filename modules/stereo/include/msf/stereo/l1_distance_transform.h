// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/parallel.h>
#include <opencv2/core/mat.hpp>

#include <cstdint>

namespace msf {

/// Largest distance l1DistanceTransform gives, also where the mask has no zero at all:
/// cv::distanceTransform's cap (its fixed-point maximum).
constexpr int kL1DistanceCap = 8192;

/// Exact L1 (city-block) distance in pixels from each pixel of `mask` (CV_8UC1) to the
/// nearest zero pixel of it, capped at kL1DistanceCap: the values of
/// cv::distanceTransform(mask, distance, cv::DIST_L1, 3, CV_32F), computed in two separable
/// passes on cv::parallel_for_ (the distance along each row, then forward and backward
/// column scans vectorised across columns) instead of its serial chamfer sweep, which is
/// several times slower. `type` is CV_32F (as OpenCV) or CV_16U.
/// Throws InvalidInputError for a mask that is empty or not CV_8UC1, or another type.
void l1DistanceTransform(const cv::Mat& mask, cv::Mat& distance, int type = CV_32F);

namespace l1_distance {
/// The row pass: distance along the row to the nearest zero of `mask_row` (nonzero = far
/// from a zero), capped; for callers that find the zeros of a row as they go.
void rowPass(const std::uint8_t* mask_row, int width, std::uint16_t* distance_row);

/// The column pass: `row_distance` (CV_16UC1, the row pass of every row) becomes the L1
/// distance in place; `distance` receives it as CV_32F or CV_16U (it may be row_distance).
void columnPass(cv::Mat& row_distance, cv::Mat& distance, int type);
} // namespace l1_distance

} // namespace msf
