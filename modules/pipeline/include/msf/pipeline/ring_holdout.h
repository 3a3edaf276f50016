// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/holdout.h>
#include <msf/io/frame_source.h>

#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <map>
#include <mutex>

namespace msf {

/// Evaluation protocol 4's split of every scan before any stage sees it: the held-out rings
/// (config section rings) are removed from the frame and kept, projected into camera 0, as
/// that frame's ground truth until the frame has been integrated and is scored. Used as the
/// engine's frame filter (on its loading thread) with take() on the integration thread.
class RingHoldout {
public:
  RingHoldout(const FrameSource& source, const HoldoutConfig& config) : source_(source), config_(config) {}

  /// Replaces the frame's scan by its input rings and keeps the held-out ones. Throws
  /// InvalidInputError naming the frame's scan when no ring is held out (a scan not in the
  /// sensor's order, ring after ring).
  void split(Frame& frame);
  /// The held-out depth of a frame split before, once. Throws InvalidInputError for a frame
  /// that was not split.
  cv::Mat take(std::size_t frame);

  const HoldoutConfig& config() const { return config_; }

private:
  const FrameSource& source_;
  HoldoutConfig config_;
  std::mutex mutex_;
  std::map<std::size_t, cv::Mat> depth_;
};

} // namespace msf
