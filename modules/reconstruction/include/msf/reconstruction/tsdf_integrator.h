// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/common/parallel.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/depth_weighting.h>
#include <msf/reconstruction/plane_distance.h>
#include <msf/reconstruction/scan_free_space.h>
#include <msf/reconstruction/signed_distance.h>
#include <msf/reconstruction/sweep_schedule.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <Eigen/Geometry>
#include <pcl/point_cloud.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace msf {

namespace detail {
/// What TsdfIntegrator keeps per pixel of a frame: planeDistanceScale, how far in front of and
/// behind its depth voxels are updated (along the ray), and its weight.
struct PixelBand {
  float scale, front, behind, weight;
  float free; ///< the weight of a free-space update, carving_weight included
};
/// The state that TsdfIntegrator::integrate's phases pass on (tsdf_integrator.cpp).
struct FrameView;
struct BlockList;
struct BlockChanges;
} // namespace detail

/// Integrates depth into a TsdfVolume (paper §III-C): a projective weighted running mean
/// (Curless and Levoy) per voxel, then the regularized update of eq. 7,
///   x = argmin ||x - y||^2 + lambda ||g(x)||^2,
/// with y the mean just computed and g the differences between 6-neighbouring observed
/// voxels. It is solved by Gauss-Seidel sweeps over the voxels this frame changed,
/// warm-started from y, with the voxels around them held fixed: a fixed number per frame
/// (Solve::Sweeps) or until the argmin is reached (Solve::Argmin, the paper's eq. 7 as
/// written); lambda = 0 is the plain mean.
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
  using Ptr = std::shared_ptr<TsdfIntegrator>;
  using ConstPtr = std::shared_ptr<const TsdfIntegrator>;

  /// A voxel's weight is the inverse variance of its signed distance, in m^-2: observations
  /// add 1 / sigma^2, so that a voxel seen often or closely is both more precise and harder to
  /// overwrite, and a threshold on it (MarchingCubes min_weight) is a precision. The config's
  /// word for a DepthWeighting (makeDepthWeighting).
  enum class Weighting {
    Constant,      ///< every depth has sigma = depth_sigma_m
    InverseSquare, ///< sigma = depth_sigma_m * z / (1 m), for depth whose noise grows with range
    PerPixel       ///< the frame's weight image, 1 / sigma^2 per pixel (DepthFusion's); as Constant without one
  };
  static constexpr Choice<Weighting> kWeightings[] = {
      {"per_pixel", Weighting::PerPixel}, {"constant", Weighting::Constant}, {"inverse_square", Weighting::InverseSquare}};

  /// What a voxel's signed distance measures: the config's word for a SignedDistanceModel
  /// (makeSignedDistance).
  enum class SignedDistance {
    Projective, ///< depth difference along the optical axis (KinectFusion, the paper)
    Plane       ///< distance to the observed surface's tangent plane (planeDistanceScale)
  };
  static constexpr Choice<SignedDistance> kSignedDistances[] = {{"plane", SignedDistance::Plane},
                                                                {"projective", SignedDistance::Projective}};

  /// How much each voxel's own mean counts against lambda's pull towards its neighbours.
  enum class LambdaData {
    Uniform,        ///< eq. 7 as the paper writes it: every mean counts once
    InverseVariance ///< by the voxel's weight (1 / sigma^2): what is uncertain is smoothed
  };
  static constexpr Choice<LambdaData> kLambdaData[] = {{"uniform", LambdaData::Uniform},
                                                       {"inverse_variance", LambdaData::InverseVariance}};

  /// How eq. 7 is solved each frame: the config's word for a SweepSchedule (makeSweepSchedule).
  enum class Solve {
    Sweeps, ///< `sweeps` Gauss-Seidel sweeps, warm-started: refined over frames (the project's)
    Argmin  ///< sweeps until no voxel moves more than argmin_tolerance_m: the minimizer itself
  };
  static constexpr Choice<Solve> kSolves[] = {{"sweeps", Solve::Sweeps}, {"argmin", Solve::Argmin}};

  /// Section `tsdf_integrator` of a config file.
  struct Config {
    static constexpr const char* kSection = "tsdf_integrator";
    static constexpr const char* kAbout =
        "TsdfIntegrator (paper step 5): each voxel's weighted mean, then the regularized update of eq. 7; a "
        "voxel's weight is the inverse variance of its distance (m^-2)";
    Weighting weighting = Weighting::PerPixel;
    double depth_sigma_m = 0.05;
    /// Saturates a voxel's weight (sigma 1 cm), so that it can still change.
    float max_weight = 1e4f;
    /// Depth too uncertain to place a surface (far stereo, matches in the sky) is not integrated.
    float min_pixel_weight = 0.25f;
    /// The band along a pixel's ray is at least this many of its sigmas, so that noisy depth is
    /// averaged over frames instead of clipped at the truncation.
    double truncation_sigmas = 2.0;
    bool space_carving = true;
    /// What a ray passed through is weaker evidence than the surface it hit, so a surface seen
    /// from many frames outlasts a few wrong rays while one seen once (a car that drove on) is cleared.
    double carving_weight = 1.0;
    /// carveWithScan: an oncoming car that passed the camera is never seen by it again, and
    /// stayed a ghost. Farther, a bin of the scan (0.4 degrees, 14 cm at 20 m) grows wider than a
    /// voxel and the conservative test carves less and less.
    double scan_carving_m = 20.0;
    /// Also carve along the rays of the frame's open sky (carveSky): they passed every surface,
    /// but the sky gives no depth, so a surface left in front of it (a car that drove on, depth
    /// carried over the sky) is cleared by nothing else.
    bool sky_carving = true;
    /// Also carve along the rays whose depth lies beyond max_depth_m (carveBeyondRange): they are
    /// not integrated, yet they passed every surface nearer than that, such as the edge of a car
    /// seen a moment ago where the background far behind it shows now.
    bool far_carving = true;
    /// Voxblox's drop-off: behind the surface the observation only guesses the thickness.
    bool weight_dropoff = true;
    /// The band behind a pixel reaches no deeper than its object is seen to be wide
    /// (silhouetteThickness), and at least two truncations. A pole that far stereo sees with a
    /// sigma of a metre otherwise leaves a band metres long in its shadow, which no later frame
    /// clears (driving on, they all see it through the pole) and which marching cubes meshes as
    /// a sheet along the rays. Only bands deeper than two truncations are cut: those that
    /// truncation_sigmas widens for noisy depth.
    bool silhouette_band = true;
    SignedDistance signed_distance = SignedDistance::Plane;
    PlaneDistanceConfig plane;
    double lambda = 0.0;
    /// Beyond it eq. 7 no longer regularizes but erases: a voxel's own mean counts less than a
    /// millionth against its neighbours' (a hundredth at max_weight with inverse_variance), and
    /// the surface is flattened to nothing; the float sums near their range long before 1e300.
    static constexpr double kMaxLambda = 1e6;
    /// Uniform: lambda is a pure number. InverseVariance: x = argmin sum_i W_i (x_i - y_i)^2 +
    /// lambda sum_ij (x_i - x_j)^2, W_i the voxel's weight, lambda in m^-2: a LiDAR-backed voxel
    /// (W ~ 1000) barely moves, a far stereo-only one (W ~ 10) takes its neighbours' mean, so
    /// that noisy façades are smoothed and the edges the LiDAR saw are not.
    LambdaData lambda_data = LambdaData::Uniform;
    /// 1: the solution is warm-started from the last frame, so it is refined over frames;
    /// solving each frame to convergence compounds the smoothing frame after frame.
    int sweeps = 1;
    static constexpr int kMaxSweeps = 100;
    Solve solve = Solve::Sweeps;
    /// Gauss-Seidel on eq. 7 contracts by about (6 lambda / (1 + 6 lambda))^2 a sweep (0.94 at
    /// lambda 5), so the remaining error is about 16 times argmin_tolerance_m.
    double argmin_tolerance_m = 1e-5;
    int argmin_max_sweeps = 1000; ///< (Stats::regularize_converged tells which stopped it)
    static constexpr int kMaxArgminSweeps = 100000;
    static constexpr double kMaxDepthM = 1000.0; ///< max_depth_m's bound (the volume's reach)
    double min_depth_m = 0.1;
    double max_depth_m = 40.0;
    /// What the camera sees 35-40 m ahead at its last frame was seen from beyond 40 m by the
    /// frames before, and a map cut at 40 m held it from one or two frames only.
    double precise_max_depth_m = 60.0;
    bool interpolate_depth = true;
    /// Rows are staggered: rays 3 px apart are 0.17 m apart at 40 m on KITTI, under the 0.4 m of
    /// a sub-block. The bands along a grazing ray are long, so fewer rays allocate faster.
    int allocation_stride = 3;

    template <class Keys>
    void keys(Keys& k) {
      k("weighting", weighting, kWeightings,
        "a depth's weight: per_pixel (the fusion's 1 / sigma_z^2; depth_sigma_m without a weight image), constant "
        "(sigma = depth_sigma_m) or inverse_square (sigma = depth_sigma_m * z / 1 m)");
      k("max_weight", max_weight, above(0), "a voxel's weight saturates here, m^-2");
      k("depth_sigma_m", depth_sigma_m, above(0), "sigma of a depth without a weight of its own, m");
      k("min_pixel_weight", min_pixel_weight, atLeast(0), "pixels of a smaller weight are not integrated, m^-2");
      k("truncation_sigmas", truncation_sigmas, atLeast(0),
        "the band along a pixel's ray is at least this many of its sigmas (0: the truncation alone)");
      k("space_carving", space_carving, "voxels seen in front of the band become free space (sdf = +truncation)");
      k("carving_weight", carving_weight, atLeast(0), "a free-space update weighs this times the observation");
      k("scan_carving_m", scan_carving_m, between(0, kMaxDepthM),
        "also carve with the LiDAR's scan where the camera's depth does not, or less (outside its view, and "
        "where a voxel's four pixels carve with less than the LiDAR's weight), this far from the LiDAR, m (0: off)");
      k("sky_carving", sky_carving,
        "also carve along the rays of the frame's open sky (SkyMask), in front of the LiDAR's highest returns (the "
        "clear sky's past them)");
      k("far_carving", far_carving, "also carve along the rays whose depth lies beyond max_depth_m, up to it");
      k("weight_dropoff", weight_dropoff, "behind the surface the weight falls to 0 at the band's end");
      k("silhouette_band", silhouette_band,
        "the band behind a pixel reaches no deeper than its object is seen to be wide (at least two truncations)");
      k("signed_distance", signed_distance, kSignedDistances,
        "plane: distance to the observed surface's tangent plane | projective: along the optical axis (the paper)");
      plane.keys(k);
      k("lambda", lambda, between(0, kMaxLambda),
        "eq. 7's regularization weight (0: the plain weighted mean; the paper: 5; beyond 1e6 it flattens the "
        "surface)");
      k("lambda_data", lambda_data, kLambdaData,
        "uniform: eq. 7 as written | inverse_variance: each mean counts by its weight, lambda in m^-2");
      k("sweeps", sweeps, between(0, kMaxSweeps), "Gauss-Seidel sweeps per frame over the voxels it changed");
      k("solve", solve, kSolves,
        "sweeps: that many per frame | argmin: until no voxel moves more than argmin_tolerance_m");
      k("argmin_tolerance_m", argmin_tolerance_m, above(0), "argmin stops after a sweep that moved no voxel more, m");
      k("argmin_max_sweeps", argmin_max_sweeps, between(1, kMaxArgminSweeps), "... or after this many sweeps");
      k("min_depth_m", min_depth_m, atLeast(0), "depth nearer than this is ignored, m");
      k("max_depth_m", max_depth_m, Range{0, kMaxDepthM, true, false}, "depth farther than this is ignored, m");
      k("precise_max_depth_m", precise_max_depth_m, between(0, kMaxDepthM),
        "depth known to within the truncation by its weight (LiDAR-backed) is integrated up to here, m (0: "
        "max_depth_m for all)");
      k("interpolate_depth", interpolate_depth, "bilinear depth between 4 pixels that agree, else the nearest");
      k("allocation_stride", allocation_stride, atLeast(1),
        "blocks are allocated along the rays of every n-th pixel in each direction (1 for sparse depth)");
    }
    /// Throws ConfigError naming the first value out of range.
    void validate() const;
  };

  /// What the last call did, with its time split (milliseconds).
  struct Stats {
    std::size_t blocks_touched = 0;
    std::size_t blocks_allocated = 0;
    std::size_t voxels_updated = 0;
    std::size_t voxels_projected = 0; ///< voxels of sub-blocks (4^3) that the depth range did not rule out
    double allocate_ms = 0, update_ms = 0, regularize_ms = 0;
    int regularize_sweeps = 0;          ///< Gauss-Seidel sweeps of eq. 7 this frame
    bool regularize_converged = false;  ///< Solve::Argmin: the tolerance was reached
  };

  /// The integrator writes into `volume`, which must outlive it.
  explicit TsdfIntegrator(TsdfVolume& volume);
  TsdfIntegrator(TsdfVolume& volume, const Config& config);

  const Config& getConfig() const { return config_; }
  /// Also sets the weighting, the signed distance and the sweep schedule that the config names
  /// (makeDepthWeighting, makeSignedDistance, makeSweepSchedule).
  void setConfig(const Config& config);
  /// Weighs depth by `weighting` instead of the config's (not null).
  void setWeighting(DepthWeighting::ConstPtr weighting);
  const DepthWeighting& weighting() const { return *weighting_; }
  /// Measures the signed distance by `model` instead of the config's (not null).
  void setSignedDistance(SignedDistanceModel::ConstPtr model);
  const SignedDistanceModel& signedDistance() const { return *signed_distance_; }
  /// Solves eq. 7 by `schedule` instead of the config's (not null).
  void setSweepSchedule(SweepSchedule::ConstPtr schedule);
  const SweepSchedule& sweepSchedule() const { return *sweep_schedule_; }
  /// The largest depth a pixel is integrated at: max(max_depth_m, precise_max_depth_m) when the
  /// frame's own weights say which depth is precise (DepthWeighting::takesFrameWeights), else
  /// max_depth_m.
  double farthestDepth() const;
  double getLambda() const { return config_.lambda; }
  void setLambda(double lambda);
  TsdfVolume& volume() { return volume_; }
  const Stats& lastStats() const { return stats_; }

  /// Integrates a depth frame seen from T_world_cam (camera to world).
  /// Throws InvalidInputError (see DepthFrame::validate).
  void integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam);
  /// The blocks that the surface bands of `frame`'s pixels cross from T_world_cam: those
  /// integrate() allocates in an empty volume, counted without allocating or updating any.
  /// Throws as integrate() does.
  std::size_t bandBlocks(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam);

  /// Whether carveWithScan clears anything (space carving with scan_carving_m > 0): whether a
  /// frame's scan is worth turning into a ScanFreeSpace.
  bool carvesWithScans() const { return config_.space_carving && config_.scan_carving_m > 0.0; }

  /// Free space that a LiDAR scan saw where the camera's depth says nothing or little
  /// (Config::scan_carving_m > 0): in blocks that hold a surface (a voxel with sdf < 0) within
  /// scan_carving_m of the LiDAR, each such voxel that lies in front of every return around its
  /// direction by more than the truncation, a voxel and the scan's skew (ScanFreeSpace::skew: 0.6 m
  /// for a sweep, which is not motion-compensated) takes a free-space update of `weight` (m^-2, the
  /// LiDAR's inverse variance) times carving_weight, unless the camera carved it as much. Without
  /// `camera_carved`, the camera did so in its whole view from T_world_cam; with it (per pixel, the
  /// weight with which the frame's depth carved the pixel's ray, carving_weight included, 0 where
  /// it has no depth; CV_32FC1 of the camera's size), only where all four pixels around a voxel's
  /// projection carved at least the scan's weight. A crumb at a car's edge, where the fusion's
  /// depth is uncertain and carves a little a frame, is cleared by the LiDAR that made it.
  /// Conservative: only where the scan has returns, a return under the ground only down to the
  /// ground, and only voxels behind a surface (the ones that make it), so that a road seen at a
  /// grazing angle, whose returns lie around it, is left alone.
  void carveWithScan(const ScanFreeSpace& free_space, const Eigen::Isometry3d& T_world_lidar, float weight,
                     const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam,
                     const cv::Mat& camera_carved = cv::Mat());

  /// Free space that the open sky shows (Config::sky_carving, with space_carving): a ray through a
  /// pixel of open sky passed every surface, so each voxel behind a surface (sdf < 0) whose centre
  /// projects into such a pixel, from min_depth_m to farthestDepth(), takes a free-space update of
  /// `weight` (m^-2) times carving_weight. `sky_depth` (CV_32FC1 of `camera`'s size; the fused
  /// cloud's field, DepthImageFusion::findOpenSky's image) holds each pixel's bound: NaN where the
  /// pixel is not open sky; a depth (that of its column's highest LiDAR return,
  /// SkyMask::topReturnDepth) in front of which, by more than the truncation and a voxel, the ray
  /// is carved, so that a blank wall above the returns that the mask takes for sky is kept; +inf
  /// where the whole ray is carved (the clear sky, SkyMask::clearSky, clipped or blue as a wall
  /// rarely is, so that a wall's top an earlier frame carried too high, against the sky now at the
  /// returns' depth, is cleared too). Throws InvalidInputError for an image of another type or
  /// size, a bound that is neither NaN nor above 0, a weight that is not positive and finite, or
  /// a pose that is not rigid.
  void carveSky(const cv::Mat& sky_depth, const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam,
                float weight);

  /// Free space that the rays beyond the range show (Config::far_carving, with space_carving): a
  /// pixel of `frame` whose depth lies beyond max_depth_m by more than truncation_sigmas of its
  /// sigma (its weight's; any depth without weights) passed every surface nearer than that; each
  /// voxel behind a surface (sdf < 0) nearer than max_depth_m by more than the truncation and a
  /// voxel, whose footprint in the image lies wholly within such pixels, takes a free-space update
  /// of `weight` (m^-2) times carving_weight. The footprint keeps the silhouettes of thin objects
  /// (a pole against a far façade), whose voxels straddle the pixels beside them. Throws
  /// InvalidInputError for a weight that is not positive and finite, or a pose that is not rigid.
  void carveBeyondRange(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam, float weight);

  /// What a frame showed free beside its depth (integrateFrame): the weight of its free-space
  /// updates (m^-2; the pipeline's is a LiDAR return's), its scan's rays and its open sky.
  struct FreeSpace {
    float weight = 0.f;
    const ScanFreeSpace* scan = nullptr; ///< the scan's rays (carveWithScan), or none
    Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
    cv::Mat sky_depth;                   ///< the open sky and its rays' bounds (carveSky), or empty
    PinholeCamera sky_camera;            ///< the camera of sky_depth
  };

  /// A frame as msf_reconstruct integrates it: its depth (integrate), then the free space its
  /// scan (when carvesWithScans()), its open sky and its rays beyond the range show
  /// (carveWithScan, carveSky, carveBeyondRange). Throws as they do; a sky depth that carveSky
  /// would carve with and refuses, before the volume changes.
  void integrateFrame(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam, const FreeSpace& free);

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

  /// How far from the sensor (metres) integration can change blocks that exist: a frame of
  /// `camera` updates voxels up to a depth of farthestDepth() plus twice the widest band behind a
  /// surface (a bilinear depth within the band of the nearest pixel's), along rays that are
  /// longest through the image's corners (x 1.36 the depth on KITTI's 1242 x 375 image); a
  /// scan's rays reach max_depth_m + truncation. Blocks that the bands
  /// reach farther, in front of a surface, are allocated, which the volume's BlockSource
  /// sees first. Infinite when the band behind a surface has no bound: per-pixel weights
  /// with truncation_sigmas > 0 and min_pixel_weight 0 (the band grows as a weight falls).
  double reach(const PinholeCamera& camera) const;
  /// The largest depth along the optical axis (metres) at which integrating a depth frame can
  /// allocate a block: farthestDepth() plus the widest band behind a surface. Blocks are allocated
  /// only there, in the camera's view from min_depth_m (carveWithScan and space carving only
  /// update blocks that exist); a scan (integrateScan, integrateRays) allocates along its rays
  /// instead. Infinite as reach() is.
  double allocationDepth() const;

  /// Voxels that integrate() tests at once on their nearest pixels: 16 (AVX-512), 8 (AVX2) or 4,
  /// the widest that the CPU runs, at most setMaxVoxelTestLanes'; the update of those that pass
  /// runs as wide (1 with the portable test). Every width gives the same volume.
  static int voxelTestLanes();
  /// Caps voxelTestLanes process-wide (4: the portable kernel), so that tests and benchmarks
  /// can compare the kernels; 16 (the default) lifts the cap.
  static void setMaxVoxelTestLanes(int lanes);

private:
  /// The widest band behind a surface that a pixel can have (metres; see reach).
  double widestBandBehind() const;
  /// Throws InvalidInputError when the frame's band would reach beyond the volume's index range.
  void checkReach(const Eigen::Isometry3d& T_world_cam) const;
  /// Whether the frame's own weight image weighs its depth (DepthWeighting::takesFrameWeights).
  bool takesWeightsOf(const DepthFrame& frame) const;
  /// Per pixel, the weight of the frame's depth (see DepthWeighting); 0 where there is no depth.
  void pixelWeights(const DepthFrame& frame, cv::Mat& weight);
  /// Whether eq. 7 changes anything: lambda > 0 and at least one sweep.
  bool regularizes() const { return config_.lambda > 0.0 && sweep_schedule_->maxSweeps() > 0; }
  /// |sdf| below which a changed voxel is regularized (infinite: all of them).
  float smoothingBand() const;
  // integrate's phases, in order.
  /// The frame's pixel weights (weight_) and the depth to integrate.
  detail::FrameView prepareDepth(const DepthFrame& frame);
  /// integrate(); returns the depth it integrated (FrameView::depth: without the pixels below
  /// min_pixel_weight).
  cv::Mat integrateDepth(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam);
  /// Per pixel, the weight of the frame's free-space evidence: its free_space_weight where it
  /// weighs its own depth and has one, else its pixel weights (weight_, after prepareDepth).
  const cv::Mat& freeSpaceWeights(const DepthFrame& frame) const;
  /// Per pixel, the weight with which the frame's free-space update carved its ray
  /// (freeSpaceWeights times carving_weight), 0 where `integrated` has no depth: what
  /// integrateFrame's scan carving reads.
  const cv::Mat& carvedWeights(const DepthFrame& frame, const cv::Mat& integrated);
  /// Throws InvalidInputError, as carveSky does, for a sky depth that is not CV_32FC1 of
  /// `camera`'s size or holds a bound neither NaN nor above 0.
  static void checkSkyDepth(const cv::Mat& sky_depth, const PinholeCamera& camera);
  /// Whether carveSky carves (Config::sky_carving, with space_carving).
  bool carvesSky() const { return config_.sky_carving && config_.space_carving; }
  /// carveSky once its sky depth is checked (checkSkyDepth).
  void carveCheckedSky(const cv::Mat& sky_depth, const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam,
                       float weight);
  /// Per pixel, its plane scale, bands and weights (pixels_).
  void computePixelBands(const DepthFrame& frame, const detail::FrameView& view);
  /// The frame and pose checked, then prepareDepth and computePixelBands: the view whose bands
  /// findBandSubBlocks walks.
  detail::FrameView prepareBands(const DepthFrame& frame, const Eigen::Isometry3d& T_world_cam);
  /// The sorted keys of the sub-blocks that the pixels' bands cross; also the depth ranges of
  /// the image's tiles (tile_min_, tile_max_, tile_band_).
  std::vector<std::uint64_t> findBandSubBlocks(const detail::FrameView& view, const Eigen::Isometry3d& T_world_cam);
  /// Allocates the blocks of those sub-blocks.
  detail::BlockList allocateSubBlocks(const std::vector<std::uint64_t>& keys);
  /// Space carving: adds the blocks with a surface in the view in front of the frame's depth.
  void addBlocksToCarve(const detail::FrameView& view, const Eigen::Isometry3d& T_world_cam, detail::BlockList& list);
  /// Updates the voxels of the listed sub-blocks that the frame sees.
  detail::BlockChanges updateBlocks(const DepthFrame& frame, const detail::FrameView& view,
                                    const Eigen::Isometry3d& T_world_cam, const detail::BlockList& list);
  /// The blocks changed and, for the regularization, their changed voxels' lists compacted.
  void collectChanged(const detail::BlockList& list, const detail::BlockChanges& changes,
                      std::vector<TsdfBlock*>& touched, std::vector<std::size_t>& offsets);
  /// Eq. 7 over the voxels changed_index_[offsets[i] .. offsets[i + 1]) of touched[i].
  void regularize(const std::vector<TsdfBlock*>& touched, const std::vector<std::size_t>& offsets);

  TsdfVolume& volume_;
  Config config_;
  Stats stats_;
  std::vector<float> data_term_;  // y of eq. 7 for the changed voxels, reused across frames
  std::vector<std::uint16_t> changed_index_; // local indices of the changed voxels, per block
  std::vector<float> tile_min_, tile_max_, tile_band_; // depth range and widest band of 8x8-pixel tiles, reused
  cv::Mat thickness_; // silhouetteThickness of the frame, reused
  cv::Mat scale_, extent_; // planeDistanceScale and smoothSurfaceExtent of the frame, reused
  std::vector<detail::PixelBand> pixels_; // reused
  cv::Mat masked_depth_; // the depth without the pixels below min_pixel_weight, reused
  cv::Mat carved_weight_; // carvedWeights of the frame, reused
  DepthWeighting::ConstPtr weighting_;
  SignedDistanceModel::ConstPtr signed_distance_;
  SweepSchedule::ConstPtr sweep_schedule_;
  cv::Mat weight_;       // pixelWeights of the frame: its weight image, or computed_weight_
  cv::Mat computed_weight_;
  // carveBeyondRange: the pixels whose rays reach beyond the range, their distances to the nearest
  // that does not, and the largest distance in each tile of them
  cv::Mat far_rays_, far_distance_, far_tile_max_;
  cv::Mat sky_rays_; // carveSky's open sky (255), the pixels of its sky_depth that are not NaN
};

/// "constant", "inverse_square", "per_pixel"; parse throws ConfigError naming the text.
const char* toString(TsdfIntegrator::Weighting weighting);
/// The weighting a config's word names, its sigma `depth_sigma_m`.
DepthWeighting::ConstPtr makeDepthWeighting(TsdfIntegrator::Weighting weighting, double depth_sigma_m);
TsdfIntegrator::Weighting parseWeighting(const std::string& text);
/// "sweeps", "argmin"; parse throws ConfigError naming the key and the text.
const char* toString(TsdfIntegrator::LambdaData data);
TsdfIntegrator::LambdaData parseLambdaData(const std::string& text);
const char* toString(TsdfIntegrator::Solve solve);
TsdfIntegrator::Solve parseSolve(const std::string& text);
/// The sweep schedule a config names: its solve, sweeps, argmin_tolerance_m and argmin_max_sweeps.
SweepSchedule::ConstPtr makeSweepSchedule(const TsdfIntegrator::Config& config);
/// "projective", "plane"; parse throws ConfigError naming the text.
const char* toString(TsdfIntegrator::SignedDistance distance);
TsdfIntegrator::SignedDistance parseSignedDistance(const std::string& text);
/// The signed distance a config's word names, a plane's by `plane`.
SignedDistanceModel::ConstPtr makeSignedDistance(TsdfIntegrator::SignedDistance distance,
                                                 const PlaneDistanceConfig& plane);

} // namespace msf

#include <msf/reconstruction/impl/tsdf_integrator.hpp>
