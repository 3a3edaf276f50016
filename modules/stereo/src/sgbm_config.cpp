#include <msf/common/exceptions.h>
#include <msf/stereo/sgbm_config.h>

#include <opencv2/calib3d.hpp>

namespace msf {

int SgbmConfig::opencvMode() const {
  if (mode == "sgbm_3way")
    return cv::StereoSGBM::MODE_SGBM_3WAY;
  if (mode == "sgbm")
    return cv::StereoSGBM::MODE_SGBM;
  if (mode == "hh")
    return cv::StereoSGBM::MODE_HH;
  if (mode == "hh4")
    return cv::StereoSGBM::MODE_HH4;
  throw ConfigError("stereo.mode must be sgbm | sgbm_3way | hh | hh4, not '" + mode + "'");
}

void SgbmConfig::validate() const {
  checkKeyRanges(*this);
  auto bad = [](const std::string& key, const std::string& why) { throw ConfigError("stereo." + key + " " + why); };
  if (num_disparities_px % 16 != 0)
    bad("num_disparities_px", "must be a positive multiple of 16, not " + std::to_string(num_disparities_px));
  if (block_size_px % 2 == 0)
    bad("block_size_px", "must be odd, not " + std::to_string(block_size_px));
  if (resolvedP2() <= resolvedP1())
    bad("p2", "must be greater than p1 (" + std::to_string(resolvedP2()) + " <= " + std::to_string(resolvedP1()) + ")");
  confidence.validate();
}

} // namespace msf
