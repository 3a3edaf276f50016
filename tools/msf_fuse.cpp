// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Paper step 4: fuses an interpolated LiDAR cloud and a stereo cloud of one camera (both
// organized, the LiDAR's of the image or its canvas) into one organized cloud, per pixel
// (eq. 6 or inverse variance).
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/fusion/depth_fusion.h>
#include <msf/fusion/point_types.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/impl/cloud_io.hpp>
#include <msf/pipeline/rig_adaptation.h>

#include <opencv2/imgcodecs.hpp>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/conversions.h>

#include <iostream>

using namespace pcl::console;

namespace {

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

/// What the command line sets.
struct Settings {
  std::string calib_path, image_size_text, color_path, left_path;
  bool print_config = false, overwrite = false;
  msf::DepthFusionConfig config;
  msf::RigAdaptationConfig rig;
};

/// What the fusion reads: the two clouds, and the colour and grey images when given.
struct Inputs {
  pcl::PointCloud<msf::PointXYZID>::Ptr lidar{new pcl::PointCloud<msf::PointXYZID>};
  pcl::PointCloud<msf::PointXYZRGBConfidence>::Ptr stereo{new pcl::PointCloud<msf::PointXYZRGBConfidence>};
  cv::Mat color, left;
};

/// The calibration, after the arguments are checked; the fusion config adapted to its rig.
msf::Calibration configure(const msf::tool::Arguments& files, Settings& settings) {
  if (files.size() != 3)
    throw msf::InvalidInputError("expected <lidar.pcd> <stereo.pcd> <out.pcd> (see -h)");
  const std::string ext = msf::fileExtension(files[2]);
  if (ext != ".pcd" && ext != ".ply")
    throw msf::InvalidInputError("output '" + files[2] + "' must end in .pcd or .ply");
  msf::tool::requireNewOutputs({files[2]}, settings.overwrite);
  const cv::Size image_size = msf::parseImageSize(settings.image_size_text);
  if (settings.calib_path.empty())
    throw msf::InvalidInputError("-calib PATH is required (focal length and baseline of the grey pair)");
  msf::Calibration calibration = msf::loadCalibration(settings.calib_path, image_size);
  msf::adaptToRig(settings.config, msf::rigAdaptation(settings.rig, calibration));
  if (settings.print_config)
    msf::printConfig(std::cout, settings.config);
  return calibration;
}

Inputs loadInputs(const std::string& lidar_path, const std::string& stereo_path, const Settings& settings) {
  TicToc tt;
  tt.tic();
  print_highlight("Loading ");
  print_value("%s %s ", lidar_path.c_str(), stereo_path.c_str());
  Inputs inputs;
  loadLidar(lidar_path, *inputs.lidar);
  loadStereo(stereo_path, *inputs.stereo);
  if (!settings.color_path.empty())
    inputs.color = msf::readImage(settings.color_path, cv::IMREAD_COLOR);
  if (!settings.left_path.empty()) {
    const std::string& left_path = settings.left_path;
    const pcl::PointCloud<msf::PointXYZRGBConfidence>& stereo = *inputs.stereo;
    inputs.left = msf::readImage(left_path, cv::IMREAD_GRAYSCALE);
    if (inputs.left.cols != static_cast<int>(stereo.width) || inputs.left.rows != static_cast<int>(stereo.height))
      throw msf::InvalidInputError("-left image '" + left_path + "' is " + std::to_string(inputs.left.cols) + "x" +
                                   std::to_string(inputs.left.rows) + ", the clouds are " +
                                   std::to_string(stereo.width) + "x" + std::to_string(stereo.height));
  }
  msf::tool::printDone(tt.toc(), inputs.lidar->size() + inputs.stereo->size(), "points");
  return inputs;
}

/// Fuses the clouds into `fused`, with a done line.
void fuse(const Inputs& inputs, const msf::Calibration& calibration, const msf::DepthFusionConfig& config,
          pcl::PointCloud<msf::PointXYZRGBWeight>& fused) {
  TicToc tt;
  tt.tic();
  print_highlight("Fusing ");
  print_value("(%s) ", msf::toString(config.method));
  msf::DepthFusion<> fusion(config);
  fusion.setCalibration(calibration);
  fusion.setInputLidar(inputs.lidar);
  fusion.setInputStereo(inputs.stereo);
  fusion.setInputColor(inputs.color);
  fusion.setInputImage(inputs.left);
  fusion.setFillSmallHoles(true); // the engine's depth
  fusion.fuse(fused);
  std::size_t valid = 0;
  for (const auto& p : fused)
    valid += std::isfinite(p.z);
  msf::tool::printDone(tt.toc(), valid, "pixels with depth");
}

int run(const msf::tool::Arguments& files, Settings& settings) {
  const msf::Calibration calibration = configure(files, settings);
  const Inputs inputs = loadInputs(files[0], files[1], settings);
  pcl::PointCloud<msf::PointXYZRGBWeight> fused;
  fuse(inputs, calibration, settings.config, fused);

  TicToc tt;
  tt.tic();
  print_highlight("Saving ");
  print_value("%s ", files[2].c_str());
  msf::saveCloud(files[2], fused);
  msf::tool::printDone(tt.toc(), fused.size(), "points");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  Settings settings;
  msf::DepthFusionConfig& config = settings.config;
  msf::tool::CommandLine cli(
      "msf_fuse", "<lidar.pcd> <stereo.pcd> <out.pcd> -calib PATH [options]",
      "Fuses two organized depth clouds of camera 0 of the same size, pixel by pixel, into one organized cloud with "
      "fields x y z rgb weight free_space_weight sky_depth (NaN where neither has depth; sky_depth NaN but in the "
      "open sky). A small hole (fusion.hole_fill_px) takes the nearest depth at weight 0, which msf_integrate "
      "does not integrate. lidar.pcd: interpolated LiDAR, ideally with the field 'distance' (pixels to the nearest "
      "real return; without it every point counts as a real return); msf_interpolate -canvas's canvas makes the output "
      "the canvas, the frame msf_reconstruct integrates. stereo.pcd: msf_stereo's output, ideally with "
      "'confidence' (without it every match counts as confident) and 'rgb'.");
  cli.value("-calib", "PATH", settings.calib_path,
            "KITTI odometry calib.txt, raw date folder, object calib or YAML (f B)")
      .value("-rig", "FILE", settings.calib_path,
             "the same as -calib: a rig file (docs/usage.md, \"Your own rig\") or any calibration above")
      .value("-image_size", "WxH", settings.image_size_text, "image size where no image lies beside the calibration")
      .value("-config", "FILE", [&](const std::string& path) { msf::readStageAndRig(path, config, settings.rig); },
             "YAML config, sections fusion and rig (the windows in rows between LiDAR rings follow the rig's "
             "beams, as in msf_reconstruct)")
      .value("-method", "NAME", [&](const std::string& name) { config.method = msf::parseFusionMethod(name); },
             "paper (eq. 6, dynamic weights) | uncertainty (inverse variance, default)")
      .value("-color", "PATH", settings.color_path,
             "colour camera image (image_2) to colour every fused point by projection")
      .value("-left", "PATH", settings.left_path,
             "camera 0's grey image (image_0): a LiDAR-backed wall goes on upward over the blank pixels above it "
             "(fusion.facade_extension), as in msf_reconstruct")
      .flag("-print_config", settings.print_config, "print the fusion settings in use")
      .overwriteOption(settings.overwrite);
  return cli.run(argc, argv, 3, [&](const msf::tool::Arguments& files) { return run(files, settings); });
}
