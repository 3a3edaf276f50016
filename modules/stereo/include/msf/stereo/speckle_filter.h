// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// cv::filterSpeckles(disparity, new_value, max_speckle_size, max_diff, buffer) for a
/// CV_16SC1 disparity image, with the same result, on row bands in parallel: every pixel
/// of a region of at most `max_speckle_size` pixels becomes `new_value`, a region being the
/// pixels connected through 4-neighbours whose values differ by at most `max_diff` (pixels
/// equal to `new_value` belong to none). Each band cuts its rows into runs of connected
/// pixels and labels them with union-find; the labels of regions crossing a band border
/// are then joined, and a last parallel pass clears the small regions' runs (a few times less
/// CPU than OpenCV's flood fill). `buffer` is scratch memory
/// kept between calls (five ints a pixel, mostly untouched). Throws InvalidInputError for an
/// empty image or another type.
void filterSpecklesParallel(cv::Mat& disparity, int new_value, int max_speckle_size, int max_diff, cv::Mat& buffer);

} // namespace msf
