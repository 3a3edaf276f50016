// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/stereo/sgbm_config.h>

#include <opencv2/calib3d.hpp>

#include <iterator>

namespace msf {

int SgbmConfig::opencvMode(bool guided) const {
  const std::string& name = modeFor(guided);
  if (name == "sgbm_3way" || name == "ground_3way")
    return cv::StereoSGBM::MODE_SGBM_3WAY;
  if (name == "sgbm")
    return cv::StereoSGBM::MODE_SGBM;
  if (name == "hh")
    return cv::StereoSGBM::MODE_HH;
  if (name == "hh4")
    return cv::StereoSGBM::MODE_HH4;
  throw ConfigError(std::string("stereo.") + (guided ? "mode" : "unguided_mode") + " must be " +
                    wordList(kModes, std::size(kModes)) + ", not '" + name + "'");
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
  if (resolvedP1Rise() >= resolvedP2())
    bad("p1_rise", "must be less than p2 (" + std::to_string(resolvedP1Rise()) + " >= " + std::to_string(resolvedP2()) +
                       ")");
  confidence.validate();
}

} // namespace msf
