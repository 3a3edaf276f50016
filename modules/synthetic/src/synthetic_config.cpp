#include <msf/common/exceptions.h>
#include <msf/synthetic/synthetic_config.h>

namespace msf::synthetic {

void SyntheticConfig::validate() const {
  checkKeyRanges(*this);
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

} // namespace msf::synthetic
