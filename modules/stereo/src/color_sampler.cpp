#include <msf/common/exceptions.h>
#include <msf/stereo/color_sampler.h>

#include <string>

namespace msf {

ColorSampler::ColorSampler(const cv::Mat& image, const Calibration& calibration, int camera) {
  if (camera < 0 || camera > 3)
    throw InvalidInputError("colour camera index " + std::to_string(camera) + " is not 0..3");
  if (image.empty())
    return;
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1)
    throw InvalidInputError("colour image must be 8-bit BGR or grey");
  image_ = image;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      P_[r * 4 + c] = static_cast<float>(calibration.P[camera](r, c));
}

} // namespace msf
