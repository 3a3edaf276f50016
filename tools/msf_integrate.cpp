// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_integrate: fuses organized depth clouds (camera frame, NaN = no depth) seen from known
// poses into a sparse TSDF volume (paper §III-C, eq. 7), saved as a .pcd voxel cloud; with
// -scans, each frame's LiDAR scan also clears what it saw through outside the camera's view.
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
#include <msf/reconstruction/scan_free_space.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <pcl/console/time.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
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

} // namespace

int main(int argc, char** argv) {
  std::string poses_path, output, input_dir, frames, calib, scans_dir;
  msf::TsdfVolume::Config volume_config;
  msf::TsdfIntegrator::Config config;
  msf::DepthFusionConfig fusion; // the LiDAR's range noise weighs a scan's free space
  msf::RigAdaptationConfig rig;
  bool carving = false, no_carving = false, print_config = false;
  msf::tool::CommandLine cli(
      "msf_integrate", "<depth_cloud.pcd>... -poses poses.txt -o volume.pcd [options]",
      "Integrates organized depth clouds (rectified camera 0 frame, NaN where there is no depth) into a sparse TSDF "
      "volume, the i-th cloud seen from the i-th pose (T_world_cam, KITTI odometry format). A cloud's rgb colours "
      "the voxels; a 'weight' field (1/sigma^2 of the depth, msf_fuse's) is used with -weighting per_pixel.");
  cli.value("-poses", "FILE", poses_path, "the poses, one line per cloud")
      .value("-o", "FILE", output, "the volume (.pcd)")
      .value("-input_dir", "DIR", input_dir, "also every .pcd of DIR, in name order")
      .value("-frames", "a:b", frames, "the poses of these lines (0-based) only, when the file has more")
      .value("-scans", "DIR", scans_dir,
             "every .bin (KITTI velodyne) or .pcd scan of DIR in name order, one per cloud (or the whole sequence's, "
             "picked by -frames as the poses are), in the LiDAR's frame: each "
             "clears what lies in front of its returns outside the camera's view, within "
             "tsdf_integrator.scan_carving_m of the LiDAR, as msf_reconstruct does (needs -calib with the LiDAR's "
             "extrinsics, and space carving)")
      .value("-calib", "PATH", calib,
             "camera intrinsics (KITTI calib.txt, raw folder or YAML); default: recovered from each cloud's points "
             "and pixels")
      .value("-rig", "FILE", calib, "the same as -calib: a rig file (docs/usage.md, \"Your own rig\") or any calibration above")
      .value("-config", "FILE",
             [&](const std::string& path) {
               const msf::ConfigFile file = msf::openConfigFile(path);
               file.read(volume_config);
               file.read(config);
               file.read(fusion);
               file.read(rig);
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
      .flag("-carving", carving,
            std::string("space carving on: voxels seen in front of the surface become free (default ") +
                (config.space_carving ? "on" : "off") + "; tsdf_integrator.space_carving)")
      .flag("-no_carving", no_carving, "space carving off")
      .flag("-print_config", print_config, "print the configuration in use");
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& positional) {
    std::vector<std::string> clouds = positional;
    if (!input_dir.empty()) {
      const std::vector<std::string> found = msf::filesIn(input_dir, {".pcd"}, "input folder");
      clouds.insert(clouds.end(), found.begin(), found.end());
    }
    if (clouds.empty() || poses_path.empty() || output.empty()) {
      cli.printHelp(argv[0]);
      throw msf::InvalidInputError("need depth clouds, -poses and -o");
    }
    if (msf::fileExtension(output) != ".pcd")
      throw msf::InvalidInputError("output '" + output + "' must be a .pcd file");
    if (carving && no_carving)
      throw msf::InvalidInputError("-carving and -no_carving together: choose one");
    if (carving || no_carving)
      config.space_carving = carving;
    msf::PinholeCamera camera;
    msf::Calibration calibration;
    if (cli.given("-calib") || cli.given("-rig")) {
      calibration = msf::loadCalibration(calib);
      camera = msf::PinholeCamera::fromCalibration(calibration);
      msf::adaptToRig(config, msf::rigAdaptation(rig, calibration));
    }
    msf::TsdfVolume volume(volume_config); // validates voxel size and truncation
    msf::TsdfIntegrator integrator(volume, config);
    if (print_config) {
      msf::printConfig(std::cout, volume_config);
      msf::printConfig(std::cout, config);
    }

    msf::PoseList poses = msf::loadOdometryPoses(poses_path);
    std::size_t first_frame = 0;
    if (cli.given("-frames")) {
      const msf::FrameRange range = msf::FrameRange::parse(frames);
      const int last = range.last < 0 ? static_cast<int>(poses.size()) - 1 : range.last;
      if (range.first >= static_cast<int>(poses.size()) || last >= static_cast<int>(poses.size()))
        throw msf::InvalidInputError("frames '" + frames + "' is beyond the " + std::to_string(poses.size()) +
                                     " poses of '" + poses_path + "'");
      poses = msf::PoseList(poses.begin() + range.first, poses.begin() + last + 1);
      first_frame = static_cast<std::size_t>(range.first);
    }
    if (poses.size() != clouds.size())
      throw msf::InvalidInputError(std::to_string(clouds.size()) + " depth clouds but " + std::to_string(poses.size()) +
                                   " poses in '" + poses_path + "' (one pose per cloud; -frames a:b selects poses)");

    std::vector<std::string> scans;
    if (cli.given("-scans")) {
      if (!(cli.given("-calib") || cli.given("-rig")))
        throw msf::InvalidInputError("-scans needs -calib: the LiDAR's pose is the camera's times its extrinsics");
      calibration.requireVelodyne();
      if (!config.space_carving || !(config.scan_carving_m > 0.0))
        throw msf::InvalidInputError("-scans carves free space: it needs space carving and "
                                     "tsdf_integrator.scan_carving_m > 0");
      scans = msf::filesIn(scans_dir, {".bin", ".pcd"}, "scan folder");
      // A whole sequence's folder (KITTI's velodyne/): -frames picks the scans as it picks the poses.
      if (cli.given("-frames") && scans.size() >= first_frame + clouds.size() && scans.size() > clouds.size())
        scans = std::vector<std::string>(scans.begin() + static_cast<std::ptrdiff_t>(first_frame),
                                         scans.begin() + static_cast<std::ptrdiff_t>(first_frame + clouds.size()));
      if (scans.size() != clouds.size())
        throw msf::InvalidInputError(std::to_string(clouds.size()) + " depth clouds but " +
                                     std::to_string(scans.size()) + " scans in '" + scans_dir +
                                     "' (one per cloud, or the whole sequence's with -frames a:b)");
    }
    const float scan_weight = 1.f / (fusion.lidar_range_sigma_m * fusion.lidar_range_sigma_m);

    pcl::console::TicToc tt;
    double integrate_ms = 0;
    for (std::size_t i = 0; i < clouds.size(); ++i) {
      print_highlight("Integrating ");
      print_value("%s ", clouds[i].c_str());
      tt.tic();
      pcl::PCLPointCloud2 blob;
      msf::loadCloudBlob(clouds[i], blob);
      const msf::DepthFrame frame =
          msf::toDepthFrame(blob, camera.valid() ? &camera : nullptr, "cloud '" + clouds[i] + "'");
      integrator.integrate(frame, poses[i]);
      if (!scans.empty())
        integrator.carveWithScan(msf::ScanFreeSpace(loadScan(scans[i])), poses[i] * calibration.T_cam0_velo,
                                 scan_weight, frame.camera, poses[i]);
      integrate_ms += integrator.lastStats().allocate_ms + integrator.lastStats().update_ms +
                      integrator.lastStats().regularize_ms;
      msf::tool::printDone(tt.toc(), integrator.lastStats().voxels_updated);
    }
    print_info("Volume: ");
    print_value("%zu", volume.numBlocks());
    print_info(" blocks, ");
    print_value("%zu", volume.numObservedVoxels());
    print_info(" observed voxels, ");
    print_value("%.1f", static_cast<double>(volume.memoryBytes()) / (1024.0 * 1024.0));
    print_info(" MiB; integration ");
    print_value("%.1f", integrate_ms / static_cast<double>(clouds.size()));
    print_info(" ms per frame\n");

    print_highlight("Saving ");
    print_value("%s ", output.c_str());
    tt.tic();
    volume.save(output);
    msf::tool::printDone(tt.toc(), volume.numObservedVoxels());
    return 0;
  });
}
