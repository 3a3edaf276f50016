// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Camera images as a rig records them to save space: sensor_msgs/CompressedImage (PNG or JPEG),
// on image_transport's "<image topic>/compressed", beside the uncompressed topic's CameraInfo.
#include <opencv2/core/mat.hpp>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <string>

namespace msf {

/// Whether `topic` is image_transport's compressed transport of an image ("<image>/compressed").
bool isCompressedTopic(const std::string& topic);

/// The CameraInfo topic of an image topic: its sibling camera_info, the transport's suffix
/// dropped first ("/cam/left/image_raw" and "/cam/left/image_raw/compressed": "/cam/left/camera_info").
std::string cameraInfoTopic(const std::string& image_topic);

/// A CompressedImage decoded (cv::imdecode) into the Image the encoder was given: mono8, bgr8
/// (a colour image comes back BGR whatever its format names), mono16 or bgr16, with its header.
/// Throws InvalidInputError naming `what` for a depth image (compressedDepth), a Bayer mosaic
/// (not a rectified camera's image) or data that does not decode.
sensor_msgs::ImagePtr decodeCompressedImage(const sensor_msgs::CompressedImage& message, const std::string& what);

/// A grey or BGR image, 8 or 16 bits a channel, as compressed_image_transport writes it:
/// `codec` "png" (lossless) or "jpeg" (quality 95, 8 bits only). Throws InvalidInputError for
/// another codec or an image it cannot hold.
sensor_msgs::CompressedImage compressImage(const cv::Mat& image, const std_msgs::Header& header,
                                           const std::string& codec);

} // namespace msf
