// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Paper step 3: SGBM (5-path or 3-way) on a rectified grey pair to an organized cloud in camera 0
// (x y z rgb confidence), coloured from the colour camera, and optionally the disparity as a
// KITTI 16-bit PNG.
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/calibration.h>
#include <msf/io/pinhole_camera.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/range_image/point_types.h>
#include <msf/range_image/real_returns.h>
#include <msf/stereo/point_types.h>
#include <msf/stereo/sgbm_stereo.h>

#include <opencv2/imgcodecs.hpp>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <cmath>
#include <iostream>

using namespace pcl::console;

namespace {

/// The prior's depth and, for guided matching, its real returns: the points whose `distance`
/// to the nearest real return is 0 (msf_interpolate writes that field).
void loadPrior(const std::string& path, bool guided, cv::Mat& prior, cv::Mat& guidance) {
  pcl::PCLPointCloud2 blob;
  msf::loadCloudBlob(path, blob);
  // PCL fills a missing field with zeros and only warns: a prior without x y z is no prior.
  for (const char* field : {"x", "y", "z"})
    if (pcl::getFieldIndex(blob, field) < 0)
      throw msf::InvalidInputError("-prior '" + path + "' has no field '" + field +
                                   "' (an organized depth cloud, as msf_interpolate writes)");
  if (blob.height <= 1)
    throw msf::InvalidInputError("-prior '" + path + "' is not organized (" + std::to_string(blob.width) + "x" +
                                 std::to_string(blob.height) + "): it must be the image's size");
  if (!guided || pcl::getFieldIndex(blob, "distance") < 0) {
    if (guided)
      print_warn("%s has no field 'distance' (as msf_interpolate writes): matching is not guided\n", path.c_str());
    pcl::PointCloud<pcl::PointXYZ> cloud;
    msf::fromCloudBlob(std::move(blob), cloud, path);
    prior = msf::cloudToDepthImage(cloud);
    return;
  }
  pcl::PointCloud<msf::PointXYZID> cloud;
  msf::fromCloudBlob(std::move(blob), cloud, path);
  prior = msf::cloudToDepthImage(cloud);
  cv::Mat distance(prior.size(), CV_32FC1);
  for (int v = 0; v < distance.rows; ++v)
    for (int u = 0; u < distance.cols; ++u)
      distance.at<float>(v, u) = cloud.at(u, v).distance;
  guidance = msf::realReturns(prior, distance);
}

/// What the command line sets.
struct Settings {
  std::string calib_path, image_size_text, color_path, disparity_path, prior_path;
  bool print_config = false, overwrite = false;
  msf::SgbmConfig config;
  msf::RigAdaptationConfig rig;
};

/// What the matcher reads: the grey pair, and the colour image and the prior when given.
struct Inputs {
  cv::Mat left, right, color, prior, guidance;
};

/// The calibration, after the arguments are checked; the stereo config adapted to its rig.
msf::Calibration configure(const msf::tool::Arguments& files, Settings& settings) {
  if (files.size() != 3)
    throw msf::InvalidInputError("expected <left.png> <right.png> <out.pcd> (see -h)");
  const std::string ext = msf::fileExtension(files[2]);
  if (ext != ".pcd" && ext != ".ply")
    throw msf::InvalidInputError("output '" + files[2] + "' must end in .pcd or .ply");
  const cv::Size image_size = msf::parseImageSize(settings.image_size_text);
  if (settings.calib_path.empty())
    throw msf::InvalidInputError("-calib PATH is required (focal length, baseline, colour camera)");
  if (!settings.disparity_path.empty() && msf::fileExtension(settings.disparity_path) != ".png")
    throw msf::InvalidInputError("-disparity_png '" + settings.disparity_path + "' must end in .png");
  msf::tool::requireNewOutputs({files[2], settings.disparity_path}, settings.overwrite);
  settings.config.validate();
  msf::Calibration calibration = msf::loadCalibration(settings.calib_path, image_size);
  msf::adaptToRig(settings.config, msf::rigAdaptation(settings.rig, calibration));
  if (settings.print_config)
    msf::printConfig(std::cout, settings.config);
  return calibration;
}

Inputs loadInputs(const std::string& left_path, const std::string& right_path, const Settings& settings) {
  TicToc tt;
  tt.tic();
  print_highlight("Loading ");
  print_value("%s %s ", left_path.c_str(), right_path.c_str());
  Inputs inputs;
  inputs.left = msf::readImage(left_path, cv::IMREAD_GRAYSCALE);
  inputs.right = msf::readImage(right_path, cv::IMREAD_GRAYSCALE);
  if (!settings.color_path.empty())
    inputs.color = msf::readImage(settings.color_path, cv::IMREAD_COLOR);
  if (!settings.prior_path.empty()) {
    loadPrior(settings.prior_path, settings.config.lidarGuidance(), inputs.prior, inputs.guidance);
    // The LiDAR's canvas (msf_interpolate -canvas): the image's part of it.
    const cv::Rect image = msf::imageInCanvas(inputs.prior.size(), inputs.left.size(),
                                              "-prior '" + settings.prior_path + "'");
    if (!image.empty()) {
      inputs.prior = inputs.prior(image).clone();
      if (!inputs.guidance.empty())
        inputs.guidance = inputs.guidance(image).clone();
    }
  }
  msf::tool::printDone(tt.toc(), static_cast<std::size_t>(inputs.left.total()), "pixels");
  return inputs;
}

/// Matches the pair into `cloud`, with a done line; nothing matched is a warning.
void match(const Inputs& inputs, const msf::Calibration& calibration, msf::SgbmStereo& stereo,
           pcl::PointCloud<msf::PointXYZRGBConfidence>& cloud) {
  TicToc tt;
  tt.tic();
  print_highlight("Matching ");
  stereo.setCalibration(calibration);
  stereo.setInputImages(inputs.left, inputs.right);
  stereo.setInputColor(inputs.color);
  stereo.setDepthPrior(inputs.prior);
  stereo.setGuidance(inputs.guidance);
  stereo.compute(cloud);
  std::size_t valid = 0;
  for (const auto& p : cloud)
    valid += std::isfinite(p.z);
  print_value("(%d disparities) ", stereo.getSearchedDisparities());
  msf::tool::printDone(tt.toc(), valid, "pixels with depth");
  if (valid == 0)
    print_warn("no pixel was matched: check the images (a rectified left/right pair?) and the disparity range\n");
}

int run(const msf::tool::Arguments& files, Settings& settings) {
  const msf::Calibration calibration = configure(files, settings);
  const Inputs inputs = loadInputs(files[0], files[1], settings);
  msf::SgbmStereo stereo(settings.config);
  pcl::PointCloud<msf::PointXYZRGBConfidence> cloud;
  match(inputs, calibration, stereo, cloud);

  TicToc tt;
  tt.tic();
  print_highlight("Saving ");
  print_value("%s ", files[2].c_str());
  if (!settings.disparity_path.empty())
    msf::writeKittiDisparityPng(settings.disparity_path, stereo.getDisparity());
  msf::saveCloud(files[2], cloud);
  msf::tool::printDone(tt.toc(), cloud.size(), "points");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  Settings settings;
  msf::SgbmConfig& config = settings.config;
  msf::tool::CommandLine cli(
      "msf_stereo", "<left.png> <right.png> <out.pcd> -calib PATH [options]",
      "Matches a rectified pair (KITTI image_0, image_1) with SGBM (stereo.unguided_mode, or stereo.mode where -prior "
      "guides it; stereo.engine: the native matcher or OpenCV's StereoSGBM) and writes the organized cloud of camera 0 "
      "(fields x y z rgb confidence; NaN where there is no match).");
  cli.value("-calib", "PATH", settings.calib_path, "KITTI odometry calib.txt, raw date folder, object calib or YAML")
      .value("-rig", "FILE", settings.calib_path,
             "the same as -calib: a rig file (docs/usage.md, \"Your own rig\") or any calibration above")
      .value("-image_size", "WxH", settings.image_size_text, "image size where no image lies beside the calibration")
      .value("-color", "PATH", settings.color_path,
             "colour camera image (image_2), projected for each point's colour; without it the colour is the left "
             "image's grey")
      .value("-disparity_png", "PATH", settings.disparity_path,
             "also write the disparity as a KITTI 16-bit PNG (pixels x 256)")
      .value("-prior", "PATH", settings.prior_path,
             "organized depth cloud (the interpolated LiDAR, of the image or its canvas) that narrows the search; "
             "with stereo.guidance lidar its real returns (distance 0) guide it")
      .value("-config", "FILE", [&](const std::string& path) { msf::readStageAndRig(path, config, settings.rig); },
             "YAML config, sections stereo (every SGBM parameter; the options below override it) and rig (the keys "
             "in rows between LiDAR rings follow the rig's beams, as in msf_reconstruct)")
      .value("-num_disparities", "N", config.num_disparities_px,
             "search range without a prior (multiple of 16; default {default})")
      .value("-block_size", "N", config.block_size_px, "odd block size (default {default})")
      .value("-mode", "NAME", [&](const std::string& mode) { config.mode = config.unguided_mode = mode; },
             "the paths, guided or not: ground_3way | sgbm (5 paths) | sgbm_3way | hh | hh4 (default: sgbm guided by "
             "-prior, ground_3way without)")
      .flag("-lr_check", config.left_right_check, "drop matches that fail a left-right check (twice the time)")
      .flag("-print_config", settings.print_config, "print the stereo settings in use")
      .overwriteOption(settings.overwrite);
  return cli.run(argc, argv, 3, [&](const msf::tool::Arguments& files) { return run(files, settings); });
}
