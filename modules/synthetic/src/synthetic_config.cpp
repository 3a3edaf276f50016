// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/synthetic/synthetic_config.h>

#include <string>

namespace msf::synthetic {

void SyntheticConfig::validate() const {
  validateRig();
  if (!(lidar_max_range_m > lidar_min_range_m))
    throw ConfigError("synthetic.lidar_max_range_m must be above lidar_min_range_m (" +
                      configValue(lidar_min_range_m) + "), not " + configValue(lidar_max_range_m));
  if (!(lidar_lower_elevation_deg < lidar_upper_elevation_deg - 11.0))
    throw ConfigError("synthetic.lidar_lower_elevation_deg must be more than 11 below lidar_upper_elevation_deg (the "
                      "upper block spans 10.33), not " + configValue(lidar_lower_elevation_deg));
  if (loop && frames < kLoopTurnFrames + 2)
    throw ConfigError("synthetic.frames must be >= " + std::to_string(kLoopTurnFrames + 2) +
                      " for a loop (out, the turn of " + std::to_string(kLoopTurnFrames) + " frames, back), not " +
                      std::to_string(frames));
}

void SyntheticConfig::validateRig() const {
  checkKeyRanges(*this);
  const std::vector<double>& e = lidar_beam_elevations_deg;
  if (lidar_model == "beams" && (e.empty() || e.size() > 1024))
    throw ConfigError("synthetic.lidar_beam_elevations_deg must hold 1..1024 elevations for lidar_model beams, not " +
                      std::to_string(e.size()));
  for (std::size_t i = 1; i < e.size(); ++i)
    if (!(e[i] > e[i - 1]))
      throw ConfigError("synthetic.lidar_beam_elevations_deg must rise from the lowest beam to the highest, not " +
                        configValue(e[i]) + " after " + configValue(e[i - 1]));
  if (!principal_point_px.empty() && principal_point_px.size() != 2)
    throw ConfigError("synthetic.principal_point_px must be [cx, cy] or [] (the image's centre), not " +
                      configValue(principal_point_px));
}

} // namespace msf::synthetic
