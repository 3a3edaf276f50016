// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Paper step 1: a Velodyne scan into an organized cloud of one camera's image.
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/velodyne_io.h>
#include <msf/range_image/lidar_projector.h>

#include <pcl/common/time.h>
#include <pcl/console/print.h>

#include <string>
#include <vector>

using namespace pcl::console;

int main(int argc, char** argv) {
  std::string calib_path, image_size_text;
  bool overwrite = false;
  msf::ProjectionConfig config;
  msf::tool::CommandLine cli("msf_project", "<scan.bin|scan.pcd> <out.pcd> -calib PATH [options]",
                             "Projects a Velodyne scan (velodyne frame, KITTI .bin or PointXYZI .pcd) into an "
                             "organized PointXYZI cloud of a camera's image, in its rectified frame: nearest return "
                             "per pixel, reflectance kept, NaN where no return lands.");
  cli.value("-calib", "PATH", calib_path, "KITTI odometry calib.txt, raw date folder, object calib or YAML camera file")
      .value("-rig", "FILE", calib_path, "the same as -calib: a rig file (docs/usage.md, \"Your own rig\") or any calibration above")
      .value("-image_size", "WxH", image_size_text, "image size where no image lies beside the calibration")
      .value("-config", "FILE", [&](const std::string& path) { msf::readConfigSection(path, config); },
             "YAML config, section projection; the options below override it")
      .value("-camera", "N", config.camera,
             "rectified camera 0..3 (default: {default}, or projection.camera of -config)")
      .value("-min_range", "M", config.min_range_m,
             "drop returns closer than M metres to the LiDAR (default {default})")
      .value("-max_range", "M", config.max_range_m, "drop returns farther than M metres (default {default})")
      .overwriteOption(overwrite);
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& files) {
    if (files.size() != 2)
      throw msf::InvalidInputError("expected <scan.bin|scan.pcd> <out.pcd> (see -h)");
    const std::string in = files[0], out = files[1];
    const std::string in_ext = msf::fileExtension(in);
    if (in_ext != ".bin" && in_ext != ".pcd")
      throw msf::InvalidInputError("input '" + in + "' must be a KITTI .bin scan or a .pcd cloud");
    if (msf::fileExtension(out) != ".pcd")
      throw msf::InvalidInputError("output '" + out + "' must end in .pcd");
    msf::tool::requireNewOutputs({out}, overwrite);
    const cv::Size image_size = msf::parseImageSize(image_size_text);
    if (calib_path.empty())
      throw msf::InvalidInputError("-calib PATH is required: the projection needs the camera and T_cam0_velo");
    config.validate();
    const msf::Calibration calibration = msf::loadCalibration(calib_path, image_size);
    const msf::LidarProjector projector(calibration, config);

    pcl::PointCloud<pcl::PointXYZI> scan;
    pcl::StopWatch watch;
    print_highlight("Loading ");
    print_value("%s ", in.c_str());
    if (in_ext == ".bin")
      msf::loadVelodyneBin(in, scan);
    else
      msf::loadCloud(in, scan);
    msf::tool::printDone(watch.getTime(), scan.size(), "points");

    watch.reset();
    print_highlight("Projecting ");
    print_info("into camera %d (%dx%d) ", config.camera, projector.camera().width, projector.camera().height);
    pcl::PointCloud<pcl::PointXYZI> cloud;
    projector.project(scan, cloud);
    std::size_t returns = 0;
    for (const auto& p : cloud)
      returns += std::isfinite(p.z);
    msf::tool::printDone(watch.getTime(), returns, "returns");
    if (returns == 0)
      throw msf::InvalidInputError("no return of '" + in + "' lands in camera " + std::to_string(config.camera) +
                                   ": wrong calibration or scan?");

    watch.reset();
    print_highlight("Saving ");
    print_value("%s ", out.c_str());
    msf::saveCloud(out, cloud);
    msf::tool::printDone(watch.getTime(), cloud.size(), "points");
    return 0;
  });
}
