// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_integrate: fuses organized depth clouds (camera frame, NaN = no depth) seen from known
// poses into a sparse TSDF volume (paper §III-C, eq. 7), saved as a .pcd voxel cloud. The free
// space each frame saw is carved as msf_reconstruct carves it: in front of its depth, along its
// open sky (msf_fuse's sky_depth), beyond the range, and with -scans along its LiDAR scan.
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/fusion/fusion_config.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/poses.h>
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/reconstruction/depth_frame.h>
#include <msf/reconstruction/scan_free_space.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <pcl/console/time.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

/// A LiDAR scan in its own frame: a KITTI .bin or a .pcd (msf_kitti2pcd's).
pcl::PointCloud<pcl::PointXYZI> loadScan(const std::string& path) {
  pcl::PointCloud<pcl::PointXYZI> scan;
  if (msf::fileExtension(path) == ".bin")
    msf::loadVelodyneBin(path, scan);
  else
    msf::loadCloud(path, scan);
  return scan;
}

/// The open sky a fused cloud carries (field sky_depth, msf_fuse's), in the part of the cloud
/// that is the camera's image (`image`; empty: the whole cloud). Empty when the cloud has no
/// such field.
cv::Mat skyDepthInImage(const pcl::PCLPointCloud2& blob, const cv::Rect& image, const std::string& what) {
  const cv::Mat sky_depth = msf::readSkyDepth(blob, what);
  return sky_depth.empty() || image.empty() ? sky_depth : sky_depth(image);
}

/// What the command line sets.
struct Settings {
  std::string poses_path, output, input_dir, frames, calib, scans_dir;
  msf::TsdfVolume::Config volume_config;
  msf::TsdfIntegrator::Config config;
  msf::DepthFusionConfig fusion; // the LiDAR's range noise weighs a scan's free space
  msf::RigAdaptationConfig rig;
  bool carving = false, no_carving = false, print_config = false, overwrite = false;
};

/// What is integrated: the i-th depth cloud seen from the i-th pose, with the i-th scan when
/// there are scans; `first_frame` is the line of the first pose in the poses file.
struct Frames {
  std::vector<std::string> clouds, scans;
  bool swept_scans = true; ///< the scans were swept by a spinning LiDAR (the rig's lidar.sweeping)
  msf::PoseList poses;
  std::size_t first_frame = 0;
};

/// The clouds given and those of -input_dir, checked with the other file arguments.
std::vector<std::string> listClouds(const msf::tool::CommandLine& cli, const msf::tool::Arguments& positional,
                                    const Settings& settings, const char* program) {
  std::vector<std::string> clouds = positional;
  if (!settings.input_dir.empty()) {
    const std::vector<std::string> found = msf::filesIn(settings.input_dir, {".pcd"}, "input folder");
    clouds.insert(clouds.end(), found.begin(), found.end());
  }
  if (clouds.empty() || settings.poses_path.empty() || settings.output.empty()) {
    cli.printHelp(program);
    throw msf::InvalidInputError("need depth clouds, -poses and -o");
  }
  if (msf::fileExtension(settings.output) != ".pcd")
    throw msf::InvalidInputError("output '" + settings.output + "' must be a .pcd file");
  msf::tool::requireNewOutputs({settings.output}, settings.overwrite);
  return clouds;
}

/// The poses of the lines -frames selects, one per cloud.
void selectPoses(const msf::tool::CommandLine& cli, const Settings& settings, Frames& frames) {
  const std::string& poses_path = settings.poses_path;
  frames.poses = msf::loadOdometryPoses(poses_path);
  if (cli.given("-frames")) {
    const msf::FrameRange range = msf::FrameRange::parse(settings.frames);
    const int count = static_cast<int>(frames.poses.size());
    const int last = range.last < 0 ? count - 1 : range.last;
    if (range.first >= count || last >= count)
      throw msf::InvalidInputError("frames '" + settings.frames + "' is beyond the " + std::to_string(count) +
                                   " poses of '" + poses_path + "'");
    frames.poses = msf::PoseList(frames.poses.begin() + range.first, frames.poses.begin() + last + 1);
    frames.first_frame = static_cast<std::size_t>(range.first);
  }
  if (frames.poses.size() != frames.clouds.size())
    throw msf::InvalidInputError(std::to_string(frames.clouds.size()) + " depth clouds but " +
                                 std::to_string(frames.poses.size()) + " poses in '" + poses_path +
                                 "' (one pose per cloud; -frames a:b selects poses)");
}

/// The scans of -scans, one per cloud.
void selectScans(const msf::tool::CommandLine& cli, const Settings& settings, const msf::Calibration& calibration,
                 Frames& frames) {
  if (!(cli.given("-calib") || cli.given("-rig")))
    throw msf::InvalidInputError("-scans needs -calib: the LiDAR's pose is the camera's times its extrinsics");
  calibration.requireVelodyne();
  if (!settings.config.space_carving || !(settings.config.scan_carving_m > 0.0))
    throw msf::InvalidInputError("-scans carves free space: it needs space carving and "
                                 "tsdf_integrator.scan_carving_m > 0");
  std::vector<std::string> scans = msf::filesIn(settings.scans_dir, {".bin", ".pcd"}, "scan folder");
  const std::size_t first = frames.first_frame, count = frames.clouds.size();
  // A whole sequence's folder (KITTI's velodyne/): -frames picks the scans as it picks the poses.
  if (cli.given("-frames") && scans.size() >= first + count && scans.size() > count)
    scans = std::vector<std::string>(scans.begin() + static_cast<std::ptrdiff_t>(first),
                                     scans.begin() + static_cast<std::ptrdiff_t>(first + count));
  if (scans.size() != count)
    throw msf::InvalidInputError(std::to_string(count) + " depth clouds but " + std::to_string(scans.size()) +
                                 " scans in '" + settings.scans_dir +
                                 "' (one per cloud, or the whole sequence's with -frames a:b)");
  frames.scans = scans;
  frames.swept_scans = calibration.lidar.sweeping;
}

/// The camera of a cloud: -calib's, on its canvas when the cloud is the image with a margin
/// (msf_fuse of msf_interpolate -canvas); nullptr without -calib (recovered from the points).
std::optional<msf::PinholeCamera> cloudCamera(const pcl::PCLPointCloud2& blob, const msf::PinholeCamera& camera,
                                              const std::string& what, cv::Rect& image_in_cloud) {
  image_in_cloud = cv::Rect();
  if (!camera.valid())
    return std::nullopt;
  const cv::Size size(static_cast<int>(blob.width), static_cast<int>(blob.height));
  image_in_cloud = msf::imageInCanvas(size, {camera.width, camera.height}, what);
  return image_in_cloud.empty() ? camera : camera.onCanvas(image_in_cloud, size);
}

/// Integrates every frame, a done line each, and carves the free space it saw as
/// msf_reconstruct does: the scan's, the open sky's, the rays beyond the range; returns the
/// integrator's time in ms summed over them.
double integrateFrames(const Frames& frames, const msf::PinholeCamera& camera, const msf::Calibration& calibration,
                       const msf::DepthFusionConfig& fusion, msf::TsdfIntegrator& integrator) {
  const float lidar_weight = fusion.lidarRangeWeight();
  pcl::console::TicToc tt;
  double integrate_ms = 0;
  for (std::size_t i = 0; i < frames.clouds.size(); ++i) {
    const std::string& cloud = frames.clouds[i];
    const Eigen::Isometry3d& T_world_cam = frames.poses[i];
    print_highlight("Integrating ");
    print_value("%s ", cloud.c_str());
    tt.tic();
    pcl::PCLPointCloud2 blob;
    msf::loadCloudBlob(cloud, blob);
    const std::string what = "cloud '" + cloud + "'";
    cv::Rect image;
    const std::optional<msf::PinholeCamera> cloud_camera = cloudCamera(blob, camera, what, image);
    const msf::DepthFrame frame = msf::toDepthFrame(blob, cloud_camera ? &*cloud_camera : nullptr, what);
    std::optional<msf::ScanFreeSpace> scan;
    if (!frames.scans.empty())
      scan.emplace(loadScan(frames.scans[i]), frames.swept_scans);
    msf::TsdfIntegrator::FreeSpace free;
    free.weight = lidar_weight;
    free.scan = scan ? &*scan : nullptr;
    free.T_world_lidar = T_world_cam * calibration.T_cam0_velo;
    free.sky_depth = skyDepthInImage(blob, image, what);
    free.sky_camera = image.empty() ? frame.camera : camera;
    integrator.integrateFrame(frame, T_world_cam, free);
    const msf::TsdfIntegrator::Stats& stats = integrator.lastStats();
    integrate_ms += stats.allocate_ms + stats.update_ms + stats.regularize_ms;
    msf::tool::printDone(tt.toc(), stats.voxels_updated, "voxels");
  }
  return integrate_ms;
}

void printVolume(const msf::TsdfVolume& volume, double integrate_ms_per_frame) {
  print_info("Volume: ");
  print_value("%zu", volume.numBlocks());
  print_info(" blocks, ");
  print_value("%zu", volume.numObservedVoxels());
  print_info(" observed voxels, ");
  print_value("%.1f", static_cast<double>(volume.memoryBytes()) / (1024.0 * 1024.0));
  print_info(" MiB; integration ");
  print_value("%.1f", integrate_ms_per_frame);
  print_info(" ms per frame\n");
}

int run(const msf::tool::CommandLine& cli, const msf::tool::Arguments& positional, Settings& settings,
        const char* program) {
  Frames frames;
  frames.clouds = listClouds(cli, positional, settings, program);
  msf::TsdfIntegrator::Config& config = settings.config;
  if (settings.carving && settings.no_carving)
    throw msf::InvalidInputError("-carving and -no_carving together: choose one");
  if (settings.carving || settings.no_carving)
    config.space_carving = settings.carving;
  msf::PinholeCamera camera;
  msf::Calibration calibration;
  if (cli.given("-calib") || cli.given("-rig")) {
    calibration = msf::loadCalibration(settings.calib);
    camera = msf::PinholeCamera::fromCalibration(calibration);
    msf::adaptToRig(config, msf::rigAdaptation(settings.rig, calibration));
  }
  msf::TsdfVolume volume(settings.volume_config); // validates voxel size and truncation
  msf::TsdfIntegrator integrator(volume, config);
  if (settings.print_config) {
    msf::printConfig(std::cout, settings.volume_config);
    msf::printConfig(std::cout, config);
  }
  selectPoses(cli, settings, frames);
  if (cli.given("-scans"))
    selectScans(cli, settings, calibration, frames);

  const double integrate_ms = integrateFrames(frames, camera, calibration, settings.fusion, integrator);
  printVolume(volume, integrate_ms / static_cast<double>(frames.clouds.size()));

  pcl::console::TicToc tt;
  print_highlight("Saving ");
  print_value("%s ", settings.output.c_str());
  tt.tic();
  volume.save(settings.output);
  msf::tool::printDone(tt.toc(), volume.numObservedVoxels(), "voxels");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  Settings settings;
  msf::TsdfVolume::Config& volume_config = settings.volume_config;
  msf::TsdfIntegrator::Config& config = settings.config;
  msf::tool::CommandLine cli(
      "msf_integrate", "<depth_cloud.pcd>... -poses poses.txt -o volume.pcd [options]",
      "Integrates organized depth clouds (rectified camera 0 frame, NaN where there is no depth) into a sparse TSDF "
      "volume, the i-th cloud seen from the i-th pose (T_world_cam, KITTI odometry format). A cloud's rgb colours "
      "the voxels; a 'weight' field (1/sigma^2 of the depth, msf_fuse's) is used with -weighting per_pixel, and "
      "msf_fuse's 'free_space_weight' and 'sky_depth' weigh and carve the free space. msf_fuse's clouds of the "
      "LiDAR's canvas (msf_interpolate -canvas) with -calib, the scans (-scans) and msf_reconstruct's -config give "
      "msf_reconstruct's map.");
  cli.value("-poses", "FILE", settings.poses_path, "the poses, one line per cloud")
      .value("-o", "FILE", settings.output, "the volume (.pcd)")
      .value("-input_dir", "DIR", settings.input_dir, "also every .pcd of DIR, in name order")
      .value("-frames", "a:b", settings.frames, "the poses of these lines (0-based) only, when the file has more")
      .value("-scans", "DIR", settings.scans_dir,
             "every .bin (KITTI velodyne) or .pcd scan of DIR in name order, one per cloud (or the whole sequence's, "
             "picked by -frames as the poses are), in the LiDAR's frame: each "
             "clears what lies in front of its returns where the cloud's depth does not, within "
             "tsdf_integrator.scan_carving_m of the LiDAR, as msf_reconstruct does (needs -calib with the LiDAR's "
             "extrinsics, and space carving; a -rig with lidar.sweeping false: scans of one instant, no sweep's skew)")
      .value("-calib", "PATH", settings.calib,
             "camera intrinsics (KITTI calib.txt, raw folder or YAML); default: recovered from each cloud's points "
             "and pixels")
      .value("-rig", "FILE", settings.calib,
             "the same as -calib: a rig file (docs/usage.md, \"Your own rig\") or any calibration above")
      .value("-config", "FILE",
             [&](const std::string& path) {
               const msf::ConfigFile file = msf::openConfigFile(path);
               file.read(volume_config);
               file.read(config);
               file.read(settings.fusion);
               file.read(settings.rig);
             },
             "YAML with sections tsdf_volume, tsdf_integrator, fusion (the LiDAR's range noise) and rig (with "
             "-calib, max_depth_m at most stereo's trusted depth, as in msf_reconstruct); the options below override "
             "it")
      .value("-voxel", "M", volume_config.voxel_size_m, "voxel size in metres (default {default})")
      .value("-trunc", "M", volume_config.truncation_m, "truncation distance in metres (default {default})")
      .value("-lambda", "L", config.lambda, "eq. 7 regularization (default {default}, the paper's KITTI value is 5)")
      .value("-max_memory", "MB", volume_config.max_memory_mb,
             "memory budget of the volume (tsdf_volume.max_memory_mb; default {default}: 3/4 of RAM)")
      .value("-sweeps", "N", config.sweeps, "Gauss-Seidel sweeps per frame (default {default})")
      .value("-weighting", "W", [&](const std::string& name) { config.weighting = msf::parseWeighting(name); },
             std::string("constant | inverse_square | per_pixel (default ") + msf::toString(config.weighting) + ")")
      .value("-max_weight", "W", config.max_weight, "weight (m^-2) at which a voxel saturates (default {default})")
      .value("-max_depth", "M", config.max_depth_m,
             "ignore depth beyond M metres (default {default}), but for -precise_max_depth's")
      .value("-precise_max_depth", "M", config.precise_max_depth_m,
             "depth whose weight field says it is known to within the truncation is integrated up to M metres "
             "(default {default}; 0: -max_depth for all)")
      .flag("-carving", settings.carving,
            std::string("space carving on: voxels seen in front of the surface become free (default ") +
                (config.space_carving ? "on" : "off") + "; tsdf_integrator.space_carving)")
      .flag("-no_carving", settings.no_carving, "space carving off")
      .flag("-print_config", settings.print_config, "print the configuration in use")
      .overwriteOption(settings.overwrite);
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& positional) {
    return run(cli, positional, settings, argv[0]);
  });
}
