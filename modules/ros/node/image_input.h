// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A camera's image topic as the node's frame sync takes it: sensor_msgs/Image, or
// CompressedImage on a topic "<image>/compressed" (image_transport's name), decoded on arrival.
#include <message_filters/simple_filter.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <functional>
#include <string>

namespace msf {

class ImageInput : public message_filters::SimpleFilter<sensor_msgs::Image> {
public:
  /// Called with the reason when an image does not decode (it then makes no frame).
  using Refusal = std::function<void(const std::string&)>;

  /// Subscribes to `topic`: compressed when its name ends in /compressed (isCompressedTopic).
  void subscribe(ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue, Refusal on_refusal);
  std::uint32_t publishers() const { return subscriber_.getNumPublishers(); }

private:
  void onCompressed(const sensor_msgs::CompressedImage::ConstPtr& message);

  ros::Subscriber subscriber_;
  std::string topic_;
  Refusal on_refusal_;
};

} // namespace msf
