// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/io/poses.h>
#include <msf/io/frame_source.h>
#include <msf/registration/adaptive_threshold.h>
#include <msf/registration/local_map.h>
#include <msf/registration/nearest_cache.h>
#include <msf/registration/point_list.h>
#include <msf/registration/scan_constraints.h>
#include <msf/registration/scan_to_map_icp.h>
#include <msf/registration/voxel_downsample.h>

#include <Eigen/Geometry>
#include <pcl/point_cloud.h>

#include <memory>
#include <string>
#include <vector>

namespace msf {

/// LiDAR odometry (the tracking module): each scan is registered to a local map of the scans
/// before it (scan to map, not scan to scan: errors do not add up frame by frame), from a
/// constant-velocity prediction, after the KISS-ICP recipe (Vizzo et al. 2023): voxel
/// downsampling, ICP with a robust kernel, and a correspondence threshold that adapts to how
/// wrong the prediction has been. Beyond it: the map keeps the plane of every voxel's returns
/// and the ICP measures distances to those planes where there are some (points slide along
/// the road instead of snapping to the rings of earlier scans); and a spinning LiDAR's sweep
/// is deskewed with the same constant velocity (deskew: sweep; msf_synth's scans are
/// snapshots). A scan whose planes leave a degree of freedom unconstrained (a single plane,
/// an empty road) is an error, not a pose that merely repeats the prediction.
class LidarOdometry {
public:
  using Ptr = std::shared_ptr<LidarOdometry>;
  using ConstPtr = std::shared_ptr<const LidarOdometry>;

  /// Section `odometry` of a config file.
  struct Config {
    static constexpr const char* kSection = "odometry";
    static constexpr const char* kAbout =
        "LidarOdometry (msf_odometry; msf_reconstruct -poses estimate): each scan registered to a local map of "
        "the scans before it";
    double voxel_size_m = 1.0;
    double min_range_m = 3.0;
    double max_range_m = 100.0;
    /// 10: the planes come from every return (PointMoments), so the points only need to be a
    /// nearest neighbour; fewer make the search faster (KISS-ICP keeps 20).
    int max_points_per_voxel = 10;
    bool point_to_plane = true;
    /// auto: resolveDeskew makes it none for a synthetic sequence and sweep otherwise (and
    /// LidarOdometry takes it as sweep).
    std::string deskew = "auto";
    double initial_threshold_m = 2.0;
    double min_correction_m = 0.1;
    int max_iterations = 100;
    double convergence = 1e-4;
    /// KITTI's scans have 0.016 or more, the synthetic street 0.003 or more, a single plane 0.
    double min_constraint = 1e-3;
    /// A measured motion's accuracy per scan (registerPoints with a prior: a GPS/INS's poses),
    /// one standard deviation: the weight of its soft constraint, where each scan pair counts
    /// as a measurement of the robust kernel's scale. 0.1 degrees is an OXTS RT3003's stated
    /// heading accuracy; 0.1 m lets the scans correct the motion a heading error turns aside.
    double prior_translation_sigma_m = 0.1;
    double prior_rotation_sigma_deg = 0.1;

    template <class Keys>
    void keys(Keys& k) {
      k("voxel_size_m", voxel_size_m, above(0),
        "voxel of the local map, m; scans are kept at half of it and registered at 1.5 times it");
      k("min_range_m", min_range_m, atLeast(0), "returns nearer (the car itself) are dropped, m");
      k("max_range_m", max_range_m, above(0), "returns farther are dropped, and the map keeps this around the sensor, m");
      k("max_points_per_voxel", max_points_per_voxel, atLeast(1), "points the map keeps per voxel");
      k("point_to_plane", point_to_plane, "distances to the map's planes where its voxels are planar, else to points");
      k("deskew", deskew, {"auto", "sweep", "none"},
        "motion compensation: sweep (a spinning LiDAR), none (snapshots), auto (none on a synthetic sequence)");
      k("initial_threshold_m", initial_threshold_m, above(0), "correspondence distance until a frame has moved, m");
      k("min_correction_m", min_correction_m, atLeast(0),
        "corrections of the prediction smaller than this are no samples of its error, m");
      k("max_iterations", max_iterations, atLeast(1), "ICP iterations per scan at most");
      k("convergence", convergence, above(0), "ICP stops when a step moves the pose less than this");
      k("min_constraint", min_constraint, Range{0, 1, false, true},
        "a scan whose planes pin a degree of freedom down less than this (smallest eigenvalue) is an error");
      k("prior_translation_sigma_m", prior_translation_sigma_m, above(0),
        "a measured motion's (a GPS/INS's poses: -poses refine) accuracy per scan, one standard deviation: the "
        "weight of its soft constraint on the registration, m");
      k("prior_rotation_sigma_deg", prior_rotation_sigma_deg, above(0),
        "the same for the measured motion's rotation, degrees");
    }
    /// Throws ConfigError naming the key of a value out of range.
    void validate() const;
  };

  /// What the last registerScan did.
  struct Stats {
    std::size_t input_points = 0;   ///< finite returns within range
    std::size_t map_points_added = 0; ///< the scan at half a voxel
    std::size_t source_points = 0;  ///< the scan registered, at 1.5 voxels
    std::size_t map_points = 0;     ///< the local map after the scan
    int iterations = 0;
    std::size_t searches = 0;       ///< searches of the map (NearestCache: the other queries reused an answer)
    std::size_t correspondences = 0;
    double threshold_m = 0;         ///< correspondence distance used
    double constraint = 0;          ///< ScanConstraints::weakest of the scan
  };

  LidarOdometry();
  /// Throws ConfigError naming a bad key.
  explicit LidarOdometry(const Config& config);

  /// Registers the next scan (time order), given in its sensor's frame, and returns its pose
  /// T_world_sensor, the world being the first scan's sensor frame. Non-finite points are
  /// skipped. Throws InvalidInputError starting with `name` for a scan without a finite point
  /// in range, one whose planes leave a degree of freedom unconstrained, or one that does not
  /// overlap the map; the odometry is then unchanged.
  ///
  /// `measured_motion`, when given, is the sensor's motion since the previous scan as a GPS/INS
  /// measured it (T_previous_current): the prediction instead of the constant velocity, and a
  /// soft constraint on the registration (Config::prior_*_sigma_*, PosePrior). A scan that
  /// cannot be registered then takes the measured motion instead of being an error (the first
  /// scan's motion only says it is measured: its pose is the world's origin).
  template <typename PointT>
  Eigen::Isometry3d registerScan(const pcl::PointCloud<PointT>& scan, const std::string& name = "scan",
                                 const Eigen::Isometry3d* measured_motion = nullptr) {
    scan_.resize(scan.size()); // non-finite ones too: registerPoints counts them in its message
    for (std::size_t i = 0; i < scan.size(); ++i)
      scan_[i] = Eigen::Vector3d(scan[i].x, scan[i].y, scan[i].z);
    return registerPoints(scan_, name, measured_motion);
  }
  Eigen::Isometry3d registerPoints(const PointList& points_sensor, const std::string& name = "scan",
                                   const Eigen::Isometry3d* measured_motion = nullptr);

  /// T_world_sensor of every scan registered.
  const PoseList& poses() const { return poses_; }
  const LocalMap& map() const { return map_; }
  const Stats& lastStats() const { return stats_; }
  const Config& config() const { return config_; }

private:
  /// The scan's pose from the prediction: scan-to-map ICP (on the first scan's own map for the
  /// second scan of a sweeping LiDAR, once its motion deskews both).
  Eigen::Isometry3d align(const PointList& points_sensor, const std::string& name, const Eigen::Isometry3d& prediction,
                          const PosePrior* prior, Stats& stats);
  /// The scan's constraints; throws when its planes leave a degree of freedom unconstrained and
  /// no prior holds it.
  ScanConstraints checkConstraints(const std::string& name, Stats& stats, bool has_prior) const;
  /// The first scan's returns in range, kept until the second scan's motion deskews them.
  void keepFirstReturns(const PointList& points_sensor);
  /// Adds the scan at `pose` to the map and to the poses.
  Eigen::Isometry3d accept(const Eigen::Isometry3d& pose, Stats& stats);

  Config config_;
  LocalMap map_;
  AdaptiveThreshold threshold_;
  PoseList poses_;
  bool sweeps_;               // deskew != none
  PointList first_returns_;  // the first scan, until the second tells the motion to deskew it
  Stats stats_;
  // Buffers kept from scan to scan: a scan's 120000 returns allocated anew each time cost
  // page faults (see VoxelDownsampler).
  PointList scan_, frame_, source_, frame_world_;
  std::vector<PointMoments> moments_;
  VoxelDownsampler downsampler_;
  NearestCache neighbors_;
};

/// `registered` with its departure from `prior` (in the prior's frame, rotations as the metres
/// they move a point at the scan's lever) removed along the directions the scan's planes leave
/// free (eigenvalues of `constraints` at or below `min_constraint`): there the prior holds, not
/// what spurious pairs (a ring on a tunnel's floor) pulled the registration to. Solution
/// remapping (Zhang, Kaess and Singh, ICRA 2016).
Eigen::Isometry3d keepPriorWhereFree(const Eigen::Isometry3d& prior, const Eigen::Isometry3d& registered,
                                     const ScanConstraints& constraints, double min_constraint);

/// `config` with deskew auto resolved for `sequence`: none for a synthetic sequence (msf_synth's
/// LiDAR takes a snapshot at the frame's pose), sweep for KITTI's.
LidarOdometry::Config resolveDeskew(LidarOdometry::Config config, const FrameSource& source);

/// Camera 0's pose from the odometry's T_velo0_velo (its world is the first scan's sensor
/// frame), with the first frame's camera 0 at T_world_cam0_first (the identity in KITTI's
/// poses files).
Eigen::Isometry3d cameraPose(const Eigen::Isometry3d& T_velo0_velo, const Eigen::Isometry3d& T_cam0_velo,
                             const Eigen::Isometry3d& T_world_cam0_first = Eigen::Isometry3d::Identity());

} // namespace msf
