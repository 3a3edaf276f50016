// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "image_input.h"

#include <msf/ros/compressed_image.h>

namespace msf {

void ImageInput::subscribe(ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue, Refusal on_refusal) {
  topic_ = topic;
  on_refusal_ = std::move(on_refusal);
  if (isCompressedTopic(topic))
    subscriber_ = nh.subscribe(topic, queue, &ImageInput::onCompressed, this);
  else
    subscriber_ = nh.subscribe<sensor_msgs::Image>(
        topic, queue, [this](const sensor_msgs::Image::ConstPtr& image) { signalMessage(image); });
}

void ImageInput::onCompressed(const sensor_msgs::CompressedImage::ConstPtr& message) {
  sensor_msgs::ImageConstPtr image;
  try {
    image = decodeCompressedImage(*message, "the image on '" + topic_ + "'");
  } catch (const std::exception& e) {
    on_refusal_(e.what());
    return;
  }
  signalMessage(image);
}

} // namespace msf
