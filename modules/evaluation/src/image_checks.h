// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The evaluation's check of an image compared with a ground truth, private to the module.
#include <msf/common/exceptions.h>

#include <opencv2/core/mat.hpp>

#include <string>

namespace msf::detail {

/// Throws InvalidInputError "<context>: <name> must be CV_32FC1" or "<context>: <name> is WxH but
/// the ground truth is WxH" unless `image` is CV_32FC1 of `ground_truth_size`.
inline void requireLikeGroundTruth(const cv::Mat& image, const std::string& context, const std::string& name,
                                   const cv::Size& ground_truth_size) {
  if (image.type() != CV_32FC1)
    throw InvalidInputError(context + ": " + name + " must be CV_32FC1");
  if (image.size() != ground_truth_size)
    throw InvalidInputError(context + ": " + name + " is " + std::to_string(image.cols) + "x" +
                            std::to_string(image.rows) + " but the ground truth is " +
                            std::to_string(ground_truth_size.width) + "x" + std::to_string(ground_truth_size.height));
}

} // namespace msf::detail
