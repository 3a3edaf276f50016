// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/clear_sky.h>

#include <initializer_list>
#include <string>

namespace msf {

cv::Mat withholdClearSky(const SkyMask& sky, const cv::Mat& image, const cv::Mat& grey, const cv::Mat& returns,
                         cv::Mat& depth, cv::Mat& weight, cv::Mat& free_weight) {
  const std::initializer_list<cv::Mat*> images = {&depth, &weight, &free_weight};
  for (const cv::Mat* values : images) // all checked before any is changed
    if (!values->empty() && (values->type() != CV_32FC1 || values->size() != image.size()))
      throw InvalidInputError("withholdClearSky: the depth and weights must be CV_32FC1 of the sky image's size");
  const bool own_grey = !grey.empty() && grey.data != image.data;
  if (own_grey && (grey.type() != CV_8UC1 || grey.size() != image.size()))
    throw InvalidInputError("withholdClearSky: camera 0's grey image must be CV_8UC1 of the sky image's size");
  cv::Mat open = sky.computeWithoutBorder(image, returns);
  cv::Mat clear = sky.clearSky(image, open);
  sky.takeBorder(open);
  if (own_grey) { // within the border, where the parallax moves an edge, camera 0's own sky decides
    const cv::Mat open_in_grey = sky.computeWithoutBorder(grey, returns);
    clear = (clear & (open | open_in_grey)) | sky.clearSky(grey, open_in_grey);
  }
  for (cv::Mat* values : images)
    if (!values->empty())
      values->setTo(0.f, clear);
  return open | clear;
}

const cv::Mat& skyImage(const cv::Mat& colour, const cv::Mat& grey, const cv::Size& size) {
  return colour.type() == CV_8UC3 && colour.size() == size ? colour : grey;
}

} // namespace msf
