// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/pipeline/ring_holdout.h>

namespace msf {

void RingHoldout::split(Frame& frame) {
  const HoldoutFrame split = makeHoldoutFrame(frame, source_.calibration(), config_);
  if (split.heldout_points == 0)
    throw InvalidInputError("-holdout: " + source_.scanName(frame.index) + " has " +
                            std::to_string(split.ring_count) + " ring id(s) and none is held out (rings.modulo " +
                            std::to_string(config_.rings.modulo) + ", heldout_remainder " +
                            std::to_string(config_.rings.heldout_remainder) +
                            "): the ring hold-out needs a scan in the sensor's order, ring after ring");
  frame.scan = pcl::make_shared<pcl::PointCloud<pcl::PointXYZI>>(*split.input.scan);
  frame.point_ring.clear(); // of the whole scan
  frame.point_time_s.clear();
  const std::lock_guard<std::mutex> lock(mutex_);
  depth_[frame.index] = split.gt_depth;
}

cv::Mat RingHoldout::take(std::size_t frame) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto it = depth_.find(frame);
  if (it == depth_.end())
    throw InvalidInputError("frame " + std::to_string(frame) + " has no held-out ground truth");
  cv::Mat depth = std::move(it->second);
  depth_.erase(it);
  return depth;
}

} // namespace msf
