// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/fusion/fusion_config.h>

namespace msf {

FusionMethod parseFusionMethod(const std::string& name) {
  if (const auto method = choiceOf(kFusionMethods, name))
    return *method;
  throw ConfigError("fusion method must be " + wordList(kFusionMethods) + ", not '" + name + "'");
}

const char* toString(FusionMethod method) { return wordOf(kFusionMethods, method); }

const char* toString(PaperWeights weights) { return wordOf(kPaperWeights, weights); }

const char* toString(LidarEdgeCue cue) { return wordOf(kLidarEdgeCues, cue); }

void DepthFusionConfig::validate() const {
  checkKeyRanges(*this);
  if (!(stereo_sigma_max_px >= stereo_sigma_min_px))
    throw ConfigError("fusion.stereo_sigma_max_px must be >= stereo_sigma_min_px");
  for (const auto& [key, value] : {std::pair{"lidar_range_window_px", lidar_range_window_px},
                                   {"edge_window_rows", edge_window_rows}, {"edge_window_cols", edge_window_cols}})
    if (value % 2 == 0)
      throw ConfigError(std::string("fusion.") + key + " must be odd, not " + std::to_string(value));
}

} // namespace msf
