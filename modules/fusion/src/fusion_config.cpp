// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/fusion/fusion_config.h>

#include <ostream>

namespace msf {

FusionMethod parseFusionMethod(const std::string& name) {
  if (name == "paper")
    return FusionMethod::Paper;
  if (name == "uncertainty")
    return FusionMethod::Uncertainty;
  throw ConfigError("fusion method must be paper or uncertainty, not '" + name + "'");
}

PaperWeights parsePaperWeights(const std::string& name) {
  if (name == "relative")
    return PaperWeights::Relative;
  if (name == "as_written")
    return PaperWeights::AsWritten;
  throw ConfigError("config key 'fusion.paper_weights' must be relative or as_written, not '" + name + "'");
}

const char* toString(PaperWeights weights) { return weights == PaperWeights::AsWritten ? "as_written" : "relative"; }

const char* toString(FusionMethod method) { return method == FusionMethod::Paper ? "paper" : "uncertainty"; }

const char* toString(LidarEdgeCue cue) { return cue == LidarEdgeCue::Bend ? "bend" : "range"; }

namespace {
void positive(float value, const char* key) {
  if (!(value > 0.f))
    throw ConfigError(std::string("config key 'fusion.") + key + "' must be > 0");
}
void nonNegative(float value, const char* key) {
  if (!(value >= 0.f))
    throw ConfigError(std::string("config key 'fusion.") + key + "' must be >= 0");
}
} // namespace

void DepthFusionConfig::read(const cv::FileNode& node) {
  std::string method_name = toString(method);
  readKey(node, "method", method_name);
  try {
    method = parseFusionMethod(method_name);
  } catch (const ConfigError&) {
    throw ConfigError("config key 'fusion.method' must be paper or uncertainty, not '" + method_name + "'");
  }
  std::string weights_name = toString(paper_weights);
  readKey(node, "paper_weights", weights_name);
  paper_weights = parsePaperWeights(weights_name);
  readKey(node, "paper_lidar_gain", paper_lidar_gain);
  readKey(node, "paper_lidar_distance_px", paper_lidar_distance_px);
  readKey(node, "paper_stereo_reference_depth_m", paper_stereo_reference_depth_m);
  readKey(node, "paper_min_stereo_confidence", paper_min_stereo_confidence);
  readKey(node, "stereo_sigma_min_px", stereo_sigma_min_px);
  readKey(node, "lidar_range_sigma_m", lidar_range_sigma_m);
  readKey(node, "stereo_sigma_max_px", stereo_sigma_max_px);
  readKey(node, "lidar_sigma_px", lidar_sigma_px);
  readKey(node, "lidar_sigma_per_distance", lidar_sigma_per_distance);
  readKey(node, "lidar_sigma_per_range", lidar_sigma_per_range);
  std::string cue_name = toString(lidar_edge_cue);
  readKey(node, "lidar_edge_cue", cue_name);
  if (cue_name != "bend" && cue_name != "range")
    throw ConfigError("config key 'fusion.lidar_edge_cue' must be bend or range, not '" + cue_name + "'");
  lidar_edge_cue = cue_name == "bend" ? LidarEdgeCue::Bend : LidarEdgeCue::Range;
  readKey(node, "disagreement_k_sigma", disagreement_k_sigma);
  readKey(node, "lidar_range_window_px", lidar_range_window_px);
  readKey(node, "parallax_check", parallax_check);
  readKey(node, "parallax_max_rows", parallax_max_rows);
  readKey(node, "edge_support", edge_support);
  readKey(node, "edge_window_rows", edge_window_rows);
  readKey(node, "edge_window_cols", edge_window_cols);
  readKey(node, "edge_jump_px", edge_jump_px);
  readKey(node, "edge_tolerance_px", edge_tolerance_px);
  readKey(node, "facade_extension", facade_extension);
  readKey(node, "facade_anchor_sigma_m", facade_anchor_sigma_m);
  readKey(node, "facade_grey_tolerance", facade_grey_tolerance);
  readKey(node, "facade_max_texture", facade_max_texture);
  readKey(node, "facade_sigma_per_m", facade_sigma_per_m);
  readKey(node, "facade_max_normal_y", facade_max_normal_y);
  readKey(node, "facade_max_gap_m", facade_max_gap_m);
  validate();
}

void DepthFusionConfig::validate() const {
  nonNegative(paper_lidar_gain, "paper_lidar_gain");
  positive(paper_lidar_distance_px, "paper_lidar_distance_px");
  positive(paper_stereo_reference_depth_m, "paper_stereo_reference_depth_m");
  positive(paper_min_stereo_confidence, "paper_min_stereo_confidence");
  positive(stereo_sigma_min_px, "stereo_sigma_min_px");
  positive(lidar_range_sigma_m, "lidar_range_sigma_m");
  if (!(stereo_sigma_max_px >= stereo_sigma_min_px))
    throw ConfigError("config key 'fusion.stereo_sigma_max_px' must be >= stereo_sigma_min_px");
  positive(lidar_sigma_px, "lidar_sigma_px");
  nonNegative(lidar_sigma_per_distance, "lidar_sigma_per_distance");
  nonNegative(lidar_sigma_per_range, "lidar_sigma_per_range");
  positive(disagreement_k_sigma, "disagreement_k_sigma");
  if (lidar_range_window_px < 1 || lidar_range_window_px % 2 == 0)
    throw ConfigError("config key 'fusion.lidar_range_window_px' must be odd and >= 1, not " +
                      std::to_string(lidar_range_window_px));
  if (parallax_max_rows < 1)
    throw ConfigError("config key 'fusion.parallax_max_rows' must be >= 1, not " + std::to_string(parallax_max_rows));
  for (const auto& [key, value] : {std::pair{"edge_window_rows", edge_window_rows}, {"edge_window_cols", edge_window_cols}})
    if (value < 1 || value % 2 == 0)
      throw ConfigError(std::string("config key 'fusion.") + key + "' must be odd and >= 1, not " +
                        std::to_string(value));
  positive(edge_jump_px, "edge_jump_px");
  nonNegative(edge_tolerance_px, "edge_tolerance_px");
  positive(facade_anchor_sigma_m, "facade_anchor_sigma_m");
  nonNegative(facade_grey_tolerance, "facade_grey_tolerance");
  nonNegative(facade_max_texture, "facade_max_texture");
  nonNegative(facade_sigma_per_m, "facade_sigma_per_m");
  if (!(facade_max_normal_y >= 0.f && facade_max_normal_y <= 1.f))
    throw ConfigError("config key 'fusion.facade_max_normal_y' must be within [0, 1]");
  nonNegative(facade_max_gap_m, "facade_max_gap_m");
}

void DepthFusionConfig::print(std::ostream& out) const {
  out << "fusion:\n"
      << "  method: " << toString(method) << "\n"
      << "  paper_weights: " << toString(paper_weights) << "\n"
      << "  paper_lidar_gain: " << configValue(paper_lidar_gain) << "\n"
      << "  paper_lidar_distance_px: " << configValue(paper_lidar_distance_px) << "\n"
      << "  paper_stereo_reference_depth_m: " << configValue(paper_stereo_reference_depth_m) << "\n"
      << "  paper_min_stereo_confidence: " << configValue(paper_min_stereo_confidence) << "\n"
      << "  stereo_sigma_min_px: " << configValue(stereo_sigma_min_px) << "\n"
      << "  stereo_sigma_max_px: " << configValue(stereo_sigma_max_px) << "\n"
      << "  lidar_sigma_px: " << configValue(lidar_sigma_px) << "\n"
      << "  lidar_sigma_per_distance: " << configValue(lidar_sigma_per_distance) << "\n"
      << "  lidar_sigma_per_range: " << configValue(lidar_sigma_per_range) << "\n"
      << "  lidar_edge_cue: " << toString(lidar_edge_cue) << "\n"
      << "  lidar_range_sigma_m: " << configValue(lidar_range_sigma_m) << "\n"
      << "  disagreement_k_sigma: " << configValue(disagreement_k_sigma) << "\n"
      << "  lidar_range_window_px: " << configValue(lidar_range_window_px) << "\n"
      << "  parallax_check: " << configValue(parallax_check) << "\n"
      << "  parallax_max_rows: " << configValue(parallax_max_rows) << "\n"
      << "  edge_support: " << configValue(edge_support) << "\n"
      << "  edge_window_rows: " << configValue(edge_window_rows) << "\n"
      << "  edge_window_cols: " << configValue(edge_window_cols) << "\n"
      << "  edge_jump_px: " << configValue(edge_jump_px) << "\n"
      << "  edge_tolerance_px: " << configValue(edge_tolerance_px) << "\n"
      << "  facade_extension: " << configValue(facade_extension) << "\n"
      << "  facade_anchor_sigma_m: " << configValue(facade_anchor_sigma_m) << "\n"
      << "  facade_grey_tolerance: " << configValue(facade_grey_tolerance) << "\n"
      << "  facade_max_texture: " << configValue(facade_max_texture) << "\n"
      << "  facade_sigma_per_m: " << configValue(facade_sigma_per_m) << "\n"
      << "  facade_max_normal_y: " << configValue(facade_max_normal_y) << "\n"
      << "  facade_max_gap_m: " << configValue(facade_max_gap_m) << "\n";
}

} // namespace msf
