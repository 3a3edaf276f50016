// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/synthetic_generator.h>

#include <cstddef>
#include <map>
#include <memory>

namespace msf::test {

/// One generator and its rendered frames (grey cameras, LiDAR, ground truth), shared by the
/// tests of this executable: rendering is the slow part, so each frame is rendered once.
class SharedStreet {
public:
  static SharedStreet& instance() {
    static SharedStreet street;
    return street;
  }
  const synthetic::SyntheticGenerator& generator() const { return *generator_; }
  const synthetic::SyntheticFrame& frame(std::size_t i) {
    auto it = frames_.find(i);
    if (it == frames_.end())
      it = frames_.emplace(i, generator_->renderFrame(i, false)).first;
    return it->second;
  }
  /// Only the LiDAR scan of frame i (cheap).
  pcl::PointCloud<pcl::PointXYZI> scan(std::size_t i) const {
    const auto& g = *generator_;
    return g.lidar().scan(g.sceneAt(i), g.poses()[i] * g.calibration().T_cam0_velo, i);
  }
  static synthetic::SyntheticConfig config() {
    synthetic::SyntheticConfig c;
    c.frames = 12;
    c.seed = 7;
    return c;
  }

private:
  SharedStreet() : generator_(std::make_unique<synthetic::SyntheticGenerator>(config())) {}
  std::unique_ptr<synthetic::SyntheticGenerator> generator_;
  std::map<std::size_t, synthetic::SyntheticFrame> frames_;
};

} // namespace msf::test
