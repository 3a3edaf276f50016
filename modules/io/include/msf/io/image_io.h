// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <string>

namespace msf {

/// cv::imread that throws IOError naming the file when it is missing or not an image, and
/// InvalidInputError when it is larger than limits::kMaxImageSide a side (a PNG is checked
/// from its header, before it is decoded).
/// flags: cv::ImreadModes (default: as stored).
cv::Mat readImage(const std::string& path, int flags = -1);

/// Encodes by the extension (cv::imencode) and writes atomically, checked to the end
/// (msf/common/checked_write.h); throws IOError naming the file and the reason on failure.
void writeImage(const std::string& path, const cv::Mat& image);

/// The bits a channel of `image` holds: 8 for an 8-bit image; for a 16-bit one, those its
/// brightest pixel needs (a 12-bit sensor stores 0..4095), so that neither a 12- nor a 16-bit
/// camera comes out dark. Throws InvalidInputError for other depths.
int significantBits(const cv::Mat& image);

/// 8 bits a channel: `bits` of a 16-bit image scaled to them; an 8-bit image as it is. A stereo
/// pair is scaled with pairBits, one gain for both.
cv::Mat toEightBit(const cv::Mat& image, int bits);
/// The bits of a stereo pair: its brighter image's (significantBits). Scaled each by its own
/// brightest pixel, the two images would be matched at different gains.
int pairBits(const cv::Mat& left, const cv::Mat& right);

/// KITTI 16-bit PNG (value = metres or pixels x 256, 0 = none) to CV_32F (0 = none).
/// Throws IOError when the file is not a single-channel 16-bit image.
cv::Mat readKittiDepthPng(const std::string& path);
cv::Mat readKittiDisparityPng(const std::string& path);

/// CV_32F (0, NaN or negative = none) to a KITTI 16-bit PNG; values are clamped to the
/// largest that fits (255.996). Atomic.
void writeKittiDepthPng(const std::string& path, const cv::Mat& depth);
void writeKittiDisparityPng(const std::string& path, const cv::Mat& disparity);

} // namespace msf
