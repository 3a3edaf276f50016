// Paper step 1: a Velodyne scan into an organized cloud of one camera's image.
#include <msf/common/atomic_file.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/velodyne_io.h>
#include <msf/range_image/lidar_projector.h>

#include <pcl/common/time.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <string>
#include <vector>

using namespace pcl::console;

namespace {

void printHelp(const char* name) {
  print_error("Syntax is: %s <scan.bin|scan.pcd> <out.pcd> -calib PATH [options]\n", name);
  print_info("  Projects a Velodyne scan (velodyne frame, KITTI .bin or PointXYZI .pcd) into an organized\n"
             "  PointXYZI cloud of a camera's image, in its rectified frame: nearest return per pixel,\n"
             "  reflectance kept, NaN where no return lands.\n");
  print_info("  where options are:\n");
  print_info("    -calib PATH      KITTI odometry calib.txt, raw date folder, object calib or YAML camera file\n");
  print_info("    -image_size WxH  image size where no image lies beside the calibration\n");
  print_info("    -camera N        rectified camera 0..3 (default: 0, or projection.camera of -config)\n");
  print_info("    -config FILE     YAML config, section projection\n");
  print_info("    -min_range M     drop returns closer than M metres to the LiDAR (default 0)\n");
  print_info("    -max_range M     drop returns farther than M metres (default 120)\n");
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::runWithHelp(argc, argv, "msf_project", 2, printHelp, [&] {
    const std::vector<std::string> value_options{"-calib", "-image_size", "-camera", "-config", "-min_range", "-max_range"};
    msf::tool::checkOptions(argc, argv, value_options, {});
    const auto files = msf::tool::positionalArguments(argc, argv, value_options);
    if (files.size() != 2)
      throw msf::InvalidInputError("expected <scan.bin|scan.pcd> <out.pcd> (see -h)");
    const std::string in = files[0], out = files[1];
    const std::string in_ext = msf::fileExtension(in);
    if (in_ext != ".bin" && in_ext != ".pcd")
      throw msf::InvalidInputError("input '" + in + "' must be a KITTI .bin scan or a .pcd cloud");
    if (msf::fileExtension(out) != ".pcd")
      throw msf::InvalidInputError("output '" + out + "' must end in .pcd");
    std::string calib_path, config_path;
    msf::tool::parseArgument(argc, argv, "-calib", calib_path);
    std::string image_size_text;
    msf::tool::parseArgument(argc, argv, "-image_size", image_size_text);
    const cv::Size image_size = msf::parseImageSize(image_size_text);
    if (calib_path.empty())
      throw msf::InvalidInputError("-calib PATH is required: the projection needs the camera and T_cam0_velo");
    msf::tool::parseArgument(argc, argv, "-config", config_path);

    msf::ProjectionConfig config;
    if (!config_path.empty())
      msf::readConfigSection(config_path, "projection", config);
    msf::tool::parseArgument(argc, argv, "-camera", config.camera);
    msf::tool::parseArgument(argc, argv, "-min_range", config.min_range_m);
    msf::tool::parseArgument(argc, argv, "-max_range", config.max_range_m);
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
    msf::tool::printDone(watch.getTime(), scan.size());

    watch.reset();
    print_highlight("Projecting ");
    print_info("into camera %d (%dx%d) ", config.camera, projector.camera().width, projector.camera().height);
    pcl::PointCloud<pcl::PointXYZI> cloud;
    projector.project(scan, cloud);
    std::size_t returns = 0;
    for (const auto& p : cloud)
      returns += std::isfinite(p.z);
    msf::tool::printDone(watch.getTime(), returns);
    if (returns == 0)
      throw msf::InvalidInputError("no return of '" + in + "' lands in camera " + std::to_string(config.camera) +
                                   ": wrong calibration or scan?");

    watch.reset();
    print_highlight("Saving ");
    print_value("%s ", out.c_str());
    msf::saveCloud(out, cloud);
    msf::tool::printDone(watch.getTime(), cloud.size());
    return 0;
  });
}
