#pragma once
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <Eigen/Geometry>
#include <opencv2/core/persistence.hpp>
#include <pcl/point_cloud.h>

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace msf {

/// Integrates depth into a TsdfVolume (paper §III-C): a projective weighted running mean
/// (Curless and Levoy) per voxel, then the regularized update of eq. 7,
///   x = argmin ||x - y||^2 + lambda ||g(x)||^2,
/// with y the mean just computed and g the differences between 6-neighbouring observed
/// voxels. It is solved by Gauss-Seidel sweeps over the voxels this frame changed,
/// warm-started from y, with the voxels around them held fixed; lambda = 0 is the plain mean.
///
/// Organized input (a depth image as an organized cloud or a DepthFrame) is integrated
/// voxel-centric: the blocks, and their 4^3 sub-blocks, that the truncation band of each
/// pixel's ray crosses are found in parallel and allocated serially (once per block); then
/// the voxels of those sub-blocks are projected into the image, in parallel over blocks: a
/// row of 4 voxels at a time in SIMD lanes against its nearest pixels, and the voxels that
/// pass are updated after the whole block is tested, their memory prefetched meanwhile.
/// Threads come from cv::parallel_for_, as for the stereo and fusion stages: in the pipeline,
/// where OpenCV runs one of two concurrent calls serially, integration and SGBM then take a
/// core each rather than time-sharing both.
/// An unorganized scan (a raw LiDAR sweep) is integrated by walking each point's ray from its
/// sensor origin, as VDBFusion does.
///
/// Not thread-safe: one integrator per volume at a time.
class TsdfIntegrator {
public:
  enum class Weighting {
    Constant,      ///< every observation weighs 1
    InverseSquare, ///< 1 / z^2 (z: observed depth in metres), for depth whose noise grows with range
    PerPixel       ///< the frame's weight image (the fusion stage's per-pixel weight)
  };

  struct Config {
    Weighting weighting = Weighting::Constant;
    float max_weight = 100.f;       ///< a voxel's weight saturates here, so it can still change
    bool space_carving = false;     ///< also update voxels seen in front of the band (sdf = +truncation)
    double lambda = 0.0;            ///< eq. 7; 0 = plain weighted mean, 5 = the paper's KITTI value
    /// Gauss-Seidel sweeps per frame over the changed voxels. 1: the solution is warm-started
    /// from the last frame, so it is refined over frames; solving each frame to convergence
    /// compounds the smoothing frame after frame (measured: more sweeps, larger error).
    int sweeps = 1;
    double min_depth_m = 0.1;       ///< depth outside [min, max] is ignored
    double max_depth_m = 80.0;
    bool interpolate_depth = true;  ///< bilinear depth between 4 valid pixels that agree, else nearest
    /// Blocks and sub-blocks are found along the rays of every n-th pixel in each direction
    /// (rows staggered): 2 costs a quarter of 1 on a dense depth image (rays 2 px apart are
    /// 0.11 m apart at 40 m on KITTI, sub-blocks 0.4 m) and misses about 2 % of the voxel
    /// updates (measured on KITTI 04 with SGBM depth); use 1 for sparse depth.
    int allocation_stride = 2;

    /// Overrides the keys present in a YAML section (`tsdf_integrator`): weighting
    /// (constant | inverse_square | per_pixel), max_weight, space_carving, lambda, sweeps,
    /// min_depth_m, max_depth_m, interpolate_depth, allocation_stride. Throws ConfigError naming a bad key.
    void read(const cv::FileNode& node);
    /// Throws ConfigError naming the first value out of range.
    void validate() const;
    void print(std::ostream& out) const;
  };

  /// What the last call did, with its time split (milliseconds).
  struct Stats {
    std::size_t blocks_touched = 0;
    std::size_t blocks_allocated = 0;
    std::size_t voxels_updated = 0;
    std::size_t voxels_projected = 0; ///< voxels of sub-blocks (4^3) that the depth range did not rule out
    double allocate_ms = 0, update_ms = 0, regularize_ms = 0;
  };

  /// The integrator writes into `volume`, which must outlive it.
  explicit TsdfIntegrator(TsdfVolume& volume);
  TsdfIntegrator(TsdfVolume& volume, const Config& config);

  const Config& getConfig() const { return config_; }
  void setConfig(const Config& config);
  double getLambda() const { return config_.lambda; }
  void setLambda(double lambda);
  TsdfVolume& volume() { return volume_; }
  const Stats& lastStats() const { return stats_; }

  /// Integrates a depth frame seen from T_world_cam (camera to world).
  /// Throws InvalidInputError (see DepthFrame::validate), also when the weighting is
  /// PerPixel and the frame has no weight image.
  void integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam);

  /// Integrates an organized cloud in the camera frame (NaN where there is no depth), with
  /// its colour and `weight` field when PointT has them. Without `camera`, the intrinsics are
  /// recovered from the cloud. Throws InvalidInputError when the cloud is not organized.
  template <typename PointT>
  void integrate(const pcl::PointCloud<PointT>& points_cam, const Eigen::Isometry3d& T_world_cam,
                 const PinholeCamera* camera = nullptr) {
    integrate(toDepthFrame(points_cam, camera), T_world_cam);
  }

  /// Integrates an unorganized scan given in the sensor frame, with the sensor at the origin
  /// of T_world_sensor; colour when PointT has rgb. Weighting PerPixel counts as Constant.
  template <typename PointT>
  void integrateScan(const pcl::PointCloud<PointT>& points_sensor, const Eigen::Isometry3d& T_world_sensor);

  /// The same with points already in the world frame (VDBFusion's Integrate(points, origin)).
  /// `colors_bgr` is empty or one BGR triple per point.
  void integrateRays(const std::vector<Eigen::Vector3f>& points_world, const std::vector<cv::Vec3b>& colors_bgr,
                     const Eigen::Vector3d& origin_world);

private:
  /// Eq. 7 over the voxels changed_index_[offsets[i] .. offsets[i + 1]) of touched[i].
  void regularize(const std::vector<TsdfBlock*>& touched, const std::vector<std::size_t>& offsets);

  TsdfVolume& volume_;
  Config config_;
  Stats stats_;
  std::vector<float> data_term_;  // y of eq. 7 for the changed voxels, reused across frames
  std::vector<std::uint16_t> changed_index_; // local indices of the changed voxels, per block
  std::vector<float> tile_min_, tile_max_; // depth range of 8x8-pixel tiles, reused
};

/// "constant", "inverse_square", "per_pixel"; parse throws ConfigError naming the text.
const char* toString(TsdfIntegrator::Weighting weighting);
TsdfIntegrator::Weighting parseWeighting(const std::string& text);

} // namespace msf

#include <msf/reconstruction/impl/tsdf_integrator.hpp>
