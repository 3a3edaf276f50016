// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/stereo/semi_global_matcher.h>
#include <msf/stereo/sgbm_config.h>

#include <opencv2/calib3d.hpp>

#include <ostream>

namespace msf {

namespace {
[[noreturn]] void bad(const std::string& key, const std::string& why) {
  throw ConfigError("config key 'stereo." + key + "' " + why);
}

/// A key of two words: true for `yes`, false for `no`, else a ConfigError naming both.
bool eitherWord(const std::string& key, const std::string& value, const char* yes, const char* no) {
  if (value == yes)
    return true;
  if (value == no)
    return false;
  bad(key, std::string("must be ") + yes + " or " + no + ", not '" + value + "'");
}

/// OpenCV's mode constant of a mode name, else a ConfigError naming `key`.
int opencvModeOf(const std::string& key, const std::string& mode) {
  if (mode == "sgbm_3way" || mode == "ground_3way")
    return cv::StereoSGBM::MODE_SGBM_3WAY;
  if (mode == "sgbm")
    return cv::StereoSGBM::MODE_SGBM;
  if (mode == "hh")
    return cv::StereoSGBM::MODE_HH;
  if (mode == "hh4")
    return cv::StereoSGBM::MODE_HH4;
  bad(key, "must be sgbm, sgbm_3way, ground_3way, hh or hh4, not '" + mode + "'");
}
} // namespace

int SgbmConfig::opencvMode(bool guided) const {
  return opencvModeOf(guided ? "mode" : "unguided_mode", modeFor(guided));
}

bool SgbmConfig::nativeEngine() const { return eitherWord("engine", engine, "native", "opencv"); }

bool SgbmConfig::lidarGuidance() const { return eitherWord("guidance", guidance, "lidar", "none"); }

void SgbmConfig::read(const cv::FileNode& node) {
  readKey(node, "engine", engine);
  readKey(node, "mode", mode);
  readKey(node, "unguided_mode", unguided_mode);
  readKey(node, "min_disparity_px", min_disparity_px);
  readKey(node, "num_disparities_px", num_disparities_px);
  readKey(node, "block_size_px", block_size_px);
  readKey(node, "p1", p1);
  readKey(node, "p2", p2);
  readKey(node, "p1_rise", p1_rise);
  readKey(node, "pre_filter_cap", pre_filter_cap);
  readKey(node, "uniqueness_ratio_pct", uniqueness_ratio_pct);
  readKey(node, "speckle_window_size_px", speckle_window_size_px);
  readKey(node, "speckle_range_px", speckle_range_px);
  readKey(node, "disp12_max_diff_px", disp12_max_diff_px);
  readKey(node, "left_right_check", left_right_check);
  readKey(node, "left_right_max_diff_px", left_right_max_diff_px);
  readKey(node, "match_left_border", match_left_border);
  readKey(node, "prior_search_range", prior_search_range);
  readKey(node, "prior_margin_px", prior_margin_px);
  readKey(node, "guidance", guidance);
  readKey(node, "guidance_gain", guidance_gain);
  readKey(node, "guidance_max_penalty", guidance_max_penalty);
  readKey(node, "guidance_bridge_rows", guidance_bridge_rows);
  readKey(node, "guidance_bridge_agreement", guidance_bridge_agreement);
  readKey(node, "max_depth_m", max_depth_m);
  readKey(node, "color_camera", color_camera);
  readKey(node, "confidence_hole_distance_px", confidence.hole_distance_px);
  readKey(node, "confidence_range_window_px", confidence.range_window_px);
  readKey(node, "confidence_range_free_px", confidence.range_free_px);
  readKey(node, "confidence_range_scale_px", confidence.range_scale_px);
  validate();
}

void SgbmConfig::validate() const {
  nativeEngine();
  opencvMode(true);
  opencvMode(false);
  if (num_disparities_px <= 0 || num_disparities_px % 16 != 0)
    bad("num_disparities_px", "must be a positive multiple of 16, not " + std::to_string(num_disparities_px));
  if (block_size_px < 1 || block_size_px > 11 || block_size_px % 2 == 0)
    bad("block_size_px", "must be odd and in 1..11, not " + std::to_string(block_size_px));
  if (p1 < 0)
    bad("p1", "must be >= 0 (0: 8 * block^2), not " + std::to_string(p1));
  if (p2 < 0)
    bad("p2", "must be >= 0 (0: 32 * block^2), not " + std::to_string(p2));
  if (resolvedP2() <= resolvedP1())
    bad("p2", "must be greater than p1 (" + std::to_string(resolvedP2()) + " <= " + std::to_string(resolvedP1()) + ")");
  if (p1_rise < 0)
    bad("p1_rise", "must be >= 0 (0: 3 * block^2), not " + std::to_string(p1_rise));
  if (resolvedP1Rise() >= resolvedP2())
    bad("p1_rise", "must be less than p2 (" + std::to_string(resolvedP1Rise()) + " >= " + std::to_string(resolvedP2()) +
                       ")");
  if (pre_filter_cap < 1 || pre_filter_cap > 63)
    bad("pre_filter_cap", "must be in 1..63, not " + std::to_string(pre_filter_cap));
  if (uniqueness_ratio_pct < 0 || uniqueness_ratio_pct > 100)
    bad("uniqueness_ratio_pct", "must be in 0..100, not " + std::to_string(uniqueness_ratio_pct));
  if (speckle_window_size_px < 0)
    bad("speckle_window_size_px", "must be >= 0, not " + std::to_string(speckle_window_size_px));
  if (speckle_range_px < 0)
    bad("speckle_range_px", "must be >= 0, not " + std::to_string(speckle_range_px));
  if (!(left_right_max_diff_px >= 0.f))
    bad("left_right_max_diff_px", "must be >= 0");
  if (prior_margin_px < 0)
    bad("prior_margin_px", "must be >= 0, not " + std::to_string(prior_margin_px));
  lidarGuidance();
  if (guidance_gain < 0 || guidance_gain > SemiGlobalMatcher::kMaxGuidanceGain)
    bad("guidance_gain", "must be in 0.." + std::to_string(SemiGlobalMatcher::kMaxGuidanceGain) + ", not " +
                             std::to_string(guidance_gain));
  if (guidance_max_penalty < 0 || guidance_max_penalty > SemiGlobalMatcher::kMaxGuidancePenalty)
    bad("guidance_max_penalty", "must be in 0.." + std::to_string(SemiGlobalMatcher::kMaxGuidancePenalty) +
                                    ", not " + std::to_string(guidance_max_penalty));
  if (guidance_bridge_rows < 0)
    bad("guidance_bridge_rows", "must be >= 0, not " + std::to_string(guidance_bridge_rows));
  if (!(guidance_bridge_agreement >= 0.f))
    bad("guidance_bridge_agreement", "must be >= 0");
  if (!(max_depth_m >= 0.f))
    bad("max_depth_m", "must be >= 0 (0 keeps all depths)");
  if (color_camera < 0 || color_camera > 3)
    bad("color_camera", "must be 0..3, not " + std::to_string(color_camera));
  confidence.validate();
}

void SgbmConfig::print(std::ostream& out) const {
  out << "stereo:\n"
      << "  engine: " << engine << "\n"
      << "  mode: " << mode << "\n"
      << "  unguided_mode: " << unguided_mode << "\n"
      << "  min_disparity_px: " << configValue(min_disparity_px) << "\n"
      << "  num_disparities_px: " << configValue(num_disparities_px) << "\n"
      << "  block_size_px: " << configValue(block_size_px) << "\n"
      << "  # p1, p2 and p1_rise resolved: " << resolvedP1() << ", " << resolvedP2() << " and " << resolvedP1Rise()
      << "\n"
      << "  p1: " << configValue(p1) << "\n"
      << "  p2: " << configValue(p2) << "\n"
      << "  p1_rise: " << configValue(p1_rise) << "\n"
      << "  pre_filter_cap: " << configValue(pre_filter_cap) << "\n"
      << "  uniqueness_ratio_pct: " << configValue(uniqueness_ratio_pct) << "\n"
      << "  speckle_window_size_px: " << configValue(speckle_window_size_px) << "\n"
      << "  speckle_range_px: " << configValue(speckle_range_px) << "\n"
      << "  disp12_max_diff_px: " << configValue(disp12_max_diff_px) << "\n"
      << "  left_right_check: " << configValue(left_right_check) << "\n"
      << "  left_right_max_diff_px: " << configValue(left_right_max_diff_px) << "\n"
      << "  match_left_border: " << configValue(match_left_border) << "\n"
      << "  prior_search_range: " << configValue(prior_search_range) << "\n"
      << "  prior_margin_px: " << configValue(prior_margin_px) << "\n"
      << "  guidance: " << guidance << "\n"
      << "  guidance_gain: " << configValue(guidance_gain) << "\n"
      << "  guidance_max_penalty: " << configValue(guidance_max_penalty) << "\n"
      << "  guidance_bridge_rows: " << configValue(guidance_bridge_rows) << "\n"
      << "  guidance_bridge_agreement: " << configValue(guidance_bridge_agreement) << "\n"
      << "  max_depth_m: " << configValue(max_depth_m) << "\n"
      << "  color_camera: " << configValue(color_camera) << "\n"
      << "  confidence_hole_distance_px: " << configValue(confidence.hole_distance_px) << "\n"
      << "  confidence_range_window_px: " << configValue(confidence.range_window_px) << "\n"
      << "  confidence_range_free_px: " << configValue(confidence.range_free_px) << "\n"
      << "  confidence_range_scale_px: " << configValue(confidence.range_scale_px) << "\n";
}

} // namespace msf
