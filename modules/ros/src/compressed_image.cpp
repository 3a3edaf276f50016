// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/ros/compressed_image.h>

#include <cv_bridge/cv_bridge.h>
#include <opencv2/imgcodecs.hpp>
#include <sensor_msgs/image_encodings.h>

#include <cstring>
#include <string>
#include <vector>

namespace msf {

namespace {

constexpr const char* kSuffix = "/compressed";

/// The ROS encoding of a decoded image, "" for one no camera image has.
std::string encodingOf(const cv::Mat& image) {
  namespace enc = sensor_msgs::image_encodings;
  switch (image.type()) {
  case CV_8UC1: return enc::MONO8;
  case CV_8UC3: return enc::BGR8;
  case CV_16UC1: return enc::MONO16;
  case CV_16UC3: return enc::BGR16;
  default: return "";
  }
}

} // namespace

bool isCompressedTopic(const std::string& topic) {
  const std::size_t n = std::char_traits<char>::length(kSuffix);
  return topic.size() > n && topic.compare(topic.size() - n, n, kSuffix) == 0;
}

std::string cameraInfoTopic(const std::string& image_topic) {
  const std::string image =
      isCompressedTopic(image_topic) ? image_topic.substr(0, image_topic.size() - std::strlen(kSuffix)) : image_topic;
  const std::size_t slash = image.rfind('/');
  return (slash == std::string::npos ? std::string() : image.substr(0, slash + 1)) + "camera_info";
}

sensor_msgs::ImagePtr decodeCompressedImage(const sensor_msgs::CompressedImage& message, const std::string& what) {
  const std::string& format = message.format;
  if (format.find("compressedDepth") != std::string::npos)
    throw InvalidInputError(what + ": a compressedDepth image (format '" + format +
                            "') is a depth map, not a camera's");
  if (format.rfind("bayer", 0) == 0)
    throw InvalidInputError(what + ": a Bayer mosaic (format '" + format + "') is not a rectified camera's image");
  cv::Mat image;
  try {
    image = cv::imdecode(message.data, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw InvalidInputError(what + ": the compressed image (format '" + format + "') does not decode: " + e.what());
  }
  if (image.empty())
    throw InvalidInputError(what + ": the compressed image (format '" + format + "', " +
                            std::to_string(message.data.size()) + " bytes) does not decode");
  const std::string encoding = encodingOf(image);
  if (encoding.empty())
    throw InvalidInputError(what + ": the compressed image (format '" + format + "') decodes to " +
                            std::to_string(image.channels()) + " channels of OpenCV depth " +
                            std::to_string(image.depth()) + ", not a grey or colour camera's image");
  return cv_bridge::CvImage(message.header, encoding, image).toImageMsg();
}

sensor_msgs::CompressedImage compressImage(const cv::Mat& image, const std_msgs::Header& header,
                                           const std::string& codec) {
  const std::string encoding = encodingOf(image);
  if (encoding.empty())
    throw InvalidInputError("an image of OpenCV type " + std::to_string(image.type()) +
                            " is no camera image to compress (8- or 16-bit grey or BGR)");
  std::vector<int> params;
  if (codec == "jpeg") {
    if (image.depth() != CV_8U)
      throw InvalidInputError("JPEG holds 8 bits a channel: a " + encoding + " image is compressed as png");
    params = {cv::IMWRITE_JPEG_QUALITY, 95};
  } else if (codec != "png") {
    throw InvalidInputError("images are compressed as png or jpeg, not '" + codec + "'");
  }
  sensor_msgs::CompressedImage message;
  message.header = header;
  message.format = encoding + "; " + codec + " compressed " + encoding;
  if (!cv::imencode("." + codec, image, message.data, params) || message.data.empty())
    throw InvalidInputError("a " + encoding + " image of " + std::to_string(image.cols) + "x" +
                            std::to_string(image.rows) + " could not be compressed as " + codec);
  return message;
}

} // namespace msf
