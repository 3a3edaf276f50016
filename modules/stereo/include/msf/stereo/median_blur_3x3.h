#pragma once
#include <opencv2/core/mat.hpp>

namespace msf {

/// 3x3 median of a CV_16SC1 image (a fixed-point disparity) with replicated borders:
/// cv::medianBlur(src, dst, 3)'s result, on row bands in parallel (cv::parallel_for_).
/// Each column's three values are sorted once and shared by the three windows that hold
/// them, so a pixel costs 18 vector min/max instead of the 38 of a 19-exchange sorting
/// network (AVX2 where the CPU has it); per core it is no faster than OpenCV's (0.23 ms a
/// KITTI frame), the gain is the bands. `dst` must not share data with `src`.
/// Throws InvalidInputError for an empty image or another type.
void medianBlur3x3(const cv::Mat& src, cv::Mat& dst);

} // namespace msf
