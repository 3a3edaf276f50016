// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/clear_sky.h>

#include <string>

namespace msf {

cv::Mat withholdClearSky(const SkyMask& sky, const cv::Mat& image, const cv::Mat& returns, cv::Mat& depth,
                         cv::Mat& weight, cv::Mat& free_weight) {
  const cv::Mat open = sky.compute(image, returns);
  const cv::Mat clear = sky.clearSky(image, open);
  for (cv::Mat* values : {&depth, &weight, &free_weight}) {
    if (values->empty())
      continue;
    if (values->type() != CV_32FC1 || values->size() != image.size())
      throw InvalidInputError("withholdClearSky: the depth and weights must be CV_32FC1 of the sky image's size");
    values->setTo(0.f, clear);
  }
  return open;
}

} // namespace msf
