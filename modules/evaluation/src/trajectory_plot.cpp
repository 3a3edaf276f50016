// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/line_plot.h>
#include <msf/evaluation/trajectory_plot.h>

namespace msf {

cv::Mat plotTrajectoriesFromAbove(const std::vector<std::pair<std::string, PoseList>>& trajectories) {
  if (trajectories.empty() || trajectories.front().second.empty())
    throw InvalidInputError("trajectory plot: no pose to draw");
  const Eigen::Isometry3d to_first = trajectories.front().second.front().inverse();
  LinePlot plot("Trajectory from above (first camera frame; axes scaled apart)", "forward z (m)", "left -x (m)");
  for (const auto& [name, poses] : trajectories) {
    std::vector<double> forward, left;
    for (const auto& T : poses) {
      const Eigen::Vector3d p = to_first * T.translation();
      forward.push_back(p.z());
      left.push_back(-p.x());
    }
    plot.addSeries(name, forward, left);
  }
  return plot.render();
}

} // namespace msf
