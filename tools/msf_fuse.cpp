// Paper step 4: fuses an interpolated LiDAR cloud and a stereo cloud of one camera (both
// organized, same size) into one organized cloud, per pixel (eq. 6 or inverse variance).
#include <msf/common/atomic_file.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/fusion/depth_fusion.h>
#include <msf/fusion/point_types.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/impl/cloud_io.hpp>

#include <opencv2/imgcodecs.hpp>
#include <pcl/common/io.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/conversions.h>

#include <iostream>

using namespace pcl::console;

namespace {

void printHelp(const char* name) {
  print_error("Syntax is: %s <lidar.pcd> <stereo.pcd> <out.pcd> -calib PATH [options]\n", name);
  print_info("  Fuses two organized depth clouds of camera 0 of the same size, pixel by pixel, into one\n"
             "  organized cloud with fields x y z rgb weight (NaN where neither has depth).\n"
             "  lidar.pcd: interpolated LiDAR, ideally with the field 'distance' (pixels to the nearest real\n"
             "  return; without it every point counts as a real return). stereo.pcd: msf_stereo's output,\n"
             "  ideally with 'confidence' (without it every match counts as confident) and 'rgb'.\n");
  print_info("  where options are:\n");
  print_info("    -calib PATH        KITTI odometry calib.txt, raw date folder, object calib or YAML (f B)\n");
  print_info("    -image_size WxH    image size where no image lies beside the calibration\n");
  print_info("    -method NAME       paper (eq. 6, dynamic weights) | uncertainty (inverse variance, default)\n");
  print_info("    -config FILE       YAML config, section fusion\n");
  print_info("    -color PATH        colour camera image (image_2) to colour every fused point by projection\n");
  print_info("    -print_config      print the fusion settings in use\n");
}

bool hasField(const pcl::PCLPointCloud2& blob, const char* name) { return pcl::getFieldIndex(blob, name) >= 0; }

/// The LiDAR cloud as PointXYZID: `distance` 0 (a real return) when the file has none.
void loadLidar(const std::string& path, pcl::PointCloud<msf::PointXYZID>& cloud) {
  pcl::PCLPointCloud2 blob;
  msf::loadCloudBlob(path, blob);
  if (hasField(blob, "distance")) {
    msf::loadCloud(path, cloud);
    return;
  }
  print_warn("%s has no field 'distance': every point counts as a real LiDAR return\n", path.c_str());
  pcl::PointCloud<pcl::PointXYZ> xyz;
  msf::loadCloud(path, xyz);
  pcl::copyPointCloud(xyz, cloud);
  for (auto& p : cloud)
    p.distance = 0.f;
}

/// The stereo cloud as PointXYZRGBConfidence: confidence 1 and grey colour when absent.
void loadStereo(const std::string& path, pcl::PointCloud<msf::PointXYZRGBConfidence>& cloud) {
  pcl::PCLPointCloud2 blob;
  msf::loadCloudBlob(path, blob);
  if (hasField(blob, "confidence") && (hasField(blob, "rgb") || hasField(blob, "rgba"))) {
    msf::loadCloud(path, cloud);
    return;
  }
  print_warn("%s has no field 'confidence': every stereo match counts as confident\n", path.c_str());
  if (hasField(blob, "rgb") || hasField(blob, "rgba")) {
    pcl::PointCloud<pcl::PointXYZRGB> xyzrgb;
    msf::loadCloud(path, xyzrgb);
    pcl::copyPointCloud(xyzrgb, cloud);
  } else {
    pcl::PointCloud<pcl::PointXYZ> xyz;
    msf::loadCloud(path, xyz);
    pcl::copyPointCloud(xyz, cloud);
  }
  for (auto& p : cloud)
    p.confidence = 1.f;
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::runWithHelp(argc, argv, "msf_fuse", 4, printHelp, [&] {
    const std::vector<std::string> value_options{"-calib", "-image_size", "-method", "-config", "-color"};
    msf::tool::checkOptions(argc, argv, value_options, {"-print_config"});
    const auto files = msf::tool::positionalArguments(argc, argv, value_options);
    if (files.size() != 3)
      throw msf::InvalidInputError("expected <lidar.pcd> <stereo.pcd> <out.pcd> (see -h)");
    const std::string ext = msf::fileExtension(files[2]);
    if (ext != ".pcd" && ext != ".ply")
      throw msf::InvalidInputError("output '" + files[2] + "' must end in .pcd or .ply");
    std::string calib_path, method, config_path, color_path;
    msf::tool::parseArgument(argc, argv, "-calib", calib_path);
    std::string image_size_text;
    msf::tool::parseArgument(argc, argv, "-image_size", image_size_text);
    const cv::Size image_size = msf::parseImageSize(image_size_text);
    msf::tool::parseArgument(argc, argv, "-method", method);
    msf::tool::parseArgument(argc, argv, "-config", config_path);
    msf::tool::parseArgument(argc, argv, "-color", color_path);
    if (calib_path.empty())
      throw msf::InvalidInputError("-calib PATH is required (focal length and baseline of the grey pair)");

    msf::DepthFusionConfig config;
    if (!config_path.empty())
      msf::readConfigSection(config_path, "fusion", config);
    if (!method.empty())
      config.method = msf::parseFusionMethod(method);
    if (find_switch(argc, argv, "-print_config"))
      config.print(std::cout);
    const msf::Calibration calibration = msf::loadCalibration(calib_path, image_size);

    TicToc tt;
    tt.tic();
    print_highlight("Loading ");
    print_value("%s %s ", files[0].c_str(), files[1].c_str());
    pcl::PointCloud<msf::PointXYZID>::Ptr lidar(new pcl::PointCloud<msf::PointXYZID>);
    pcl::PointCloud<msf::PointXYZRGBConfidence>::Ptr stereo(new pcl::PointCloud<msf::PointXYZRGBConfidence>);
    loadLidar(files[0], *lidar);
    loadStereo(files[1], *stereo);
    cv::Mat color;
    if (!color_path.empty())
      color = msf::readImage(color_path, cv::IMREAD_COLOR);
    msf::tool::printDone(tt.toc(), lidar->size() + stereo->size());

    tt.tic();
    print_highlight("Fusing ");
    print_value("(%s) ", msf::toString(config.method));
    msf::DepthFusion<> fusion(config);
    fusion.setCalibration(calibration);
    fusion.setInputLidar(lidar);
    fusion.setInputStereo(stereo);
    fusion.setInputColor(color);
    pcl::PointCloud<msf::PointXYZRGBWeight> fused;
    fusion.fuse(fused);
    std::size_t valid = 0;
    for (const auto& p : fused)
      valid += std::isfinite(p.z);
    msf::tool::printDone(tt.toc(), valid);

    tt.tic();
    print_highlight("Saving ");
    print_value("%s ", files[2].c_str());
    msf::saveCloud(files[2], fused);
    msf::tool::printDone(tt.toc(), fused.size());
    return 0;
  });
}
