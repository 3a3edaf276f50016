// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/evaluation/holdout.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace msf {

namespace {

/// Each point's ring: from the data when the scan carries it, else from the rig's beam
/// elevations, else from the sensor's order (KITTI's files: ring after ring).
std::vector<int> scanRingIds(const Frame& frame, const Calibration& calibration) {
  if (!frame.point_ring.empty())
    return std::vector<int>(frame.point_ring.begin(), frame.point_ring.end());
  if (!calibration.lidar.beam_elevations_deg.empty())
    return ringIdsFromElevations(*frame.scan, calibration.lidar.beam_elevations_deg);
  return ringIds(*frame.scan);
}

} // namespace

HoldoutFrame makeHoldoutFrame(const Frame& frame, const Calibration& calibration, const HoldoutConfig& config) {
  if (config.projection.camera != 0)
    throw ConfigError("protocol 2 evaluates in camera 0; projection.camera is " +
                      std::to_string(config.projection.camera));
  if (!frame.scan)
    throw InvalidInputError("frame " + std::to_string(frame.index) + " has no scan");
  HoldoutFrame out;
  auto input = pcl::make_shared<pcl::PointCloud<pcl::PointXYZI>>();
  pcl::PointCloud<pcl::PointXYZI> heldout;
  out.ring_count = splitRings(*frame.scan, scanRingIds(frame, calibration), config.rings, *input, heldout);
  out.heldout_points = heldout.size();
  const LidarProjector projector(calibration, config.projection);
  projector.projectToImage(heldout, out.gt_depth);
  projector.projectToImage(*input, out.input_depth);
  out.input.frame = frame.index;
  out.input.calibration = &calibration;
  out.input.scan = input;
  out.input.left = frame.left;
  out.input.right = frame.right;
  out.input.color = frame.color;
  out.input.has_pose = frame.has_pose;
  out.input.T_world_cam0 = frame.T_world_cam0;
  return out;
}

HoldoutEvaluation::HoldoutEvaluation(const HoldoutConfig& config) : config_(config) {
  config_.rings.validate();
  config_.projection.validate();
}

void HoldoutEvaluation::addMethod(const std::string& name, HoldoutMethod method) {
  if (name.empty())
    throw InvalidInputError("a hold-out method needs a name");
  for (const auto& m : methods_)
    if (m.first == name)
      throw InvalidInputError("hold-out method '" + name + "' is given twice");
  methods_.emplace_back(name, std::move(method));
}

void HoldoutEvaluation::addFusionBounds(const std::string& first, const std::string& second) {
  auto index = [&](const std::string& name) {
    for (std::size_t m = 0; m < methods_.size(); ++m)
      if (methods_[m].first == name)
        return m;
    std::string names;
    for (const auto& m : methods_)
      names += (names.empty() ? "" : ", ") + m.first;
    throw InvalidInputError("fusion bounds: '" + name + "' is not a method of this evaluation (its methods: " +
                            names + ")");
  };
  if (first == second)
    throw InvalidInputError("fusion bounds need two different methods, got '" + first + "' twice");
  bound_first_ = index(first);
  bound_second_ = index(second);
  bounds_ = true;
}

std::vector<HoldoutResult> HoldoutEvaluation::run(const Sequence& sequence,
                                                  const std::vector<std::size_t>& frames) const {
  if (methods_.empty())
    throw InvalidInputError("no hold-out method to run");
  const Calibration& calibration = sequence.calibration();
  const double fB = calibration.focalBaseline();
  const FusionBound kBounds[2] = {FusionBound::Select, FusionBound::Blend};
  const std::size_t rows = methods_.size() + (bounds_ ? 2 : 0); // the methods', then the bounds'
  std::vector<DepthErrorAccumulator> errors(rows);
  std::vector<std::vector<DepthErrorAccumulator>> region_errors(rows);
  std::vector<std::string> region_names;
  std::vector<std::vector<double>> times(methods_.size());
  std::vector<FusionLoss> losses(methods_.size());
  std::size_t done = 0;
  for (const std::size_t i : frames) {
    const HoldoutFrame split = makeHoldoutFrame(sequence.load(i, load_color_), calibration, config_);
    std::vector<HoldoutRegion> regions;
    if (breakdown_) {
      regions = holdoutRegions(split.gt_depth, split.input_depth, fB, config_.d1);
      region_names.clear();
      for (const auto& region : regions)
        region_names.push_back(region.name);
    }
    auto accumulate = [&](std::size_t row, const cv::Mat& estimate) {
      errors[row].add(split.gt_depth, estimate, fB, cv::Mat(), config_.d1);
      region_errors[row].resize(regions.size());
      for (std::size_t r = 0; r < regions.size(); ++r)
        region_errors[row][r].add(split.gt_depth, estimate, fB, regions[r].mask, config_.d1);
    };
    cv::Mat bound_inputs[2];
    std::vector<cv::Mat> estimates(methods_.size());
    for (std::size_t m = 0; m < methods_.size(); ++m) {
      const auto start = std::chrono::steady_clock::now();
      const cv::Mat estimate = methods_[m].second(split.input);
      const auto stop = std::chrono::steady_clock::now();
      times[m].push_back(std::chrono::duration<double, std::milli>(stop - start).count());
      if (estimate.type() != CV_32FC1 || estimate.size() != split.gt_depth.size())
        throw InvalidInputError("hold-out method '" + methods_[m].first + "' returned a " +
                                std::to_string(estimate.cols) + "x" + std::to_string(estimate.rows) +
                                " image of type " + std::to_string(estimate.type()) + ", expected CV_32FC1 " +
                                std::to_string(split.gt_depth.cols) + "x" + std::to_string(split.gt_depth.rows));
      accumulate(m, estimate);
      estimates[m] = estimate;
      if (bounds_ && (m == bound_first_ || m == bound_second_))
        bound_inputs[m == bound_first_ ? 0 : 1] = estimate;
    }
    if (bounds_) {
      for (std::size_t k = 0; k < 2; ++k)
        accumulate(methods_.size() + k, fusionBoundDepth(split.gt_depth, bound_inputs[0], bound_inputs[1], kBounds[k]));
      for (std::size_t m = 0; m < methods_.size(); ++m)
        if (m != bound_first_ && m != bound_second_)
          losses[m].add(split.gt_depth, bound_inputs[0], bound_inputs[1], estimates[m], fB, config_.d1);
    }
    if (progress_)
      progress_(++done, frames.size());
  }
  std::vector<HoldoutResult> results;
  for (std::size_t m = 0; m < rows; ++m) {
    HoldoutResult r;
    r.method = m < methods_.size() ? methods_[m].first : fusionBoundName(kBounds[m - methods_.size()]);
    r.metrics = errors[m].metrics();
    r.median_ms = m < methods_.size() ? median(times[m]) : 0.0;
    r.frames = frames.size();
    for (std::size_t k = 0; k < region_errors[m].size(); ++k)
      r.regions.push_back({region_names[k], region_errors[m][k].metrics()});
    if (bounds_ && m < methods_.size() && m != bound_first_ && m != bound_second_)
      r.lost_to_bound = losses[m];
    results.push_back(r);
  }
  return results;
}

std::string formatHoldoutTable(const std::vector<HoldoutResult>& results) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-20s %9s %9s %9s %10s %9s %9s %9s %9s %10s\n", "method", "coverage", "D1 all",
                "D1 est", "disp MAE", "MAE m", "RMSE m", "iMAE", "iRMSE", "ms/frame");
  out << line;
  for (const auto& r : results) {
    const DepthMetrics& m = r.metrics;
    std::snprintf(line, sizeof line, "%-20s %9.4f %8.2f%% %8.2f%% %8.3fpx %9.3f %9.3f %9.3f %9.3f %10.2f\n",
                  r.method.c_str(), m.coverage, 100.0 * m.d1_all, 100.0 * m.d1_estimated, m.disparity_mae_px, m.mae_m,
                  m.rmse_m, m.imae_per_km, m.irmse_per_km, r.median_ms);
    out << line;
  }
  return out.str();
}

std::string formatHoldoutBreakdown(const std::vector<HoldoutResult>& results) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-20s %-10s %9s %9s %9s %9s %10s %9s %9s %10s\n", "method", "region", "share",
                "coverage", "D1 all", "D1 est", "disp MAE", "MAE m", "RMSE m", "MAE part");
  out << line;
  for (const auto& r : results)
    for (const auto& region : r.regions) {
      const DepthMetrics& m = region.metrics;
      // share: of the ground-truth pixels; MAE part: the region's errors over all the method's
      // estimates, so that the parts of a partition add up to the method's MAE.
      const double share = r.metrics.gt_pixels ? static_cast<double>(m.gt_pixels) / r.metrics.gt_pixels : 0.0;
      const double part = r.metrics.estimated && m.estimated ? m.mae_m * m.estimated / r.metrics.estimated : 0.0;
      std::snprintf(line, sizeof line, "%-20s %-10s %8.2f%% %9.4f %8.2f%% %8.2f%% %8.3fpx %9.3f %9.3f %10.3f\n",
                    r.method.c_str(), region.region.c_str(), 100.0 * share, m.coverage, 100.0 * m.d1_all,
                    100.0 * m.d1_estimated, m.disparity_mae_px, m.mae_m, m.rmse_m, part);
      out << line;
    }
  // Where a method's MAE comes from: a few estimates on the wrong surface, or noise everywhere.
  std::snprintf(line, sizeof line, "\n%-20s %22s %10s\n", "method", "errors >= 10 m (share)", "MAE part");
  out << line;
  for (const auto& r : results) {
    std::snprintf(line, sizeof line, "%-20s %21.2f%% %10.3f\n", r.method.c_str(), 100.0 * r.metrics.gross_share,
                  r.metrics.gross_mae_part_m);
    out << line;
  }
  return out.str();
}

void writeHoldoutCsv(const std::string& path, const std::vector<HoldoutResult>& results) {
  writeStreamAtomically(path, [&](std::ostream& out) {
    out << "method,frames,gt_pixels,estimated,coverage,d1_all,d1_estimated,disparity_mae_px,mae_m,rmse_m,"
           "imae_per_km,irmse_per_km,median_ms,gross_share,gross_mae_part_m\n";
    out.precision(6);
    for (const auto& r : results) {
      const DepthMetrics& m = r.metrics;
      out << r.method << ',' << r.frames << ',' << m.gt_pixels << ',' << m.estimated << ',' << m.coverage << ','
          << m.d1_all << ',' << m.d1_estimated << ',' << m.disparity_mae_px << ',' << m.mae_m << ',' << m.rmse_m
          << ',' << m.imae_per_km << ',' << m.irmse_per_km << ',' << r.median_ms << ',' << m.gross_share << ','
          << m.gross_mae_part_m << '\n';
    }
  });
}

} // namespace msf
