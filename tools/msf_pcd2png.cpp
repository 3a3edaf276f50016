// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Writes the depth of an organized cloud as an image: a KITTI 16-bit depth PNG (default),
// a KITTI disparity PNG, or a false-colour picture with a legend in metres.
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/depth_colormap.h>
#include <msf/io/image_io.h>
#include <msf/io/organized_conversion.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <opencv2/core.hpp>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>

using namespace pcl::console;

int main(int argc, char** argv) {
  std::string calib_path;
  bool disparity = false, colour = false, overwrite = false;
  double range_min = 0, range_max = 0;
  msf::tool::CommandLine cli("msf_pcd2png", "<organized.pcd> <out.png> [options]",
                             "Writes the z of each pixel of an organized cloud (NaN = no depth) as a picture: by "
                             "default a KITTI 16-bit depth PNG (metres x 256, 0 = none).");
  cli.flag("-disparity", disparity, "KITTI 16-bit disparity PNG (pixels x 256), needs -calib")
      .value("-calib", "PATH", calib_path, "KITTI odometry calib.txt, raw date folder, object calib or YAML")
      .value("-rig", "FILE", calib_path, "the same as -calib: a rig file (docs/usage.md, \"Your own rig\") or any calibration above")
      .flag("-color", colour, "8-bit false-colour picture with a legend in metres")
      .value("-range", "MIN,MAX",
             [&](const std::string& text) {
               char rest = 0;
               if (std::sscanf(text.c_str(), "%lf,%lf%c", &range_min, &range_max, &rest) != 2 ||
                   !std::isfinite(range_min) || !std::isfinite(range_max) || range_max <= range_min)
                 throw msf::InvalidInputError("-range must be MIN,MAX in metres with MIN < MAX");
             },
             "colour range in metres for -color (default: 2nd-98th percentile)")
      .overwriteOption(overwrite);
  return cli.run(argc, argv, 2, [&](const msf::tool::Arguments& files) {
    if (files.size() != 2)
      throw msf::InvalidInputError("expected <organized.pcd> <out.png> (see -h)");
    if (msf::fileExtension(files[1]) != ".png")
      throw msf::InvalidInputError("output '" + files[1] + "' must end in .png");
    if (disparity && colour)
      throw msf::InvalidInputError("-disparity and -color exclude each other");
    if (disparity && calib_path.empty())
      throw msf::InvalidInputError("-disparity needs -calib PATH (the focal length and baseline)");
    msf::tool::requireNewOutputs({files[1]}, overwrite);

    TicToc tt;
    tt.tic();
    print_highlight("Loading ");
    print_value("%s ", files[0].c_str());
    pcl::PointCloud<pcl::PointXYZ> cloud;
    msf::loadCloud(files[0], cloud);
    msf::tool::printDone(tt.toc(), cloud.size(), "points");
    if (!cloud.isOrganized())
      throw msf::InvalidInputError("cloud '" + files[0] + "' is not organized (" + std::to_string(cloud.width) + "x" +
                                   std::to_string(cloud.height) + "): a depth image needs width x height pixels");
    const cv::Mat depth = msf::cloudToDepthImage(cloud);

    tt.tic();
    print_highlight("Saving ");
    print_value("%s ", files[1].c_str());
    // The KITTI PNG holds value x 256 in 16 bits: larger values saturate at 255.996, said.
    const auto warnSaturated = [&](const cv::Mat& values, const char* what) {
      const int n = cv::countNonZero(values >= 65535.5f / 256.f);
      if (n > 0)
        print_warn("%d pixel%s of the %s beyond the format's largest value (255.996) saturate\n", n, n > 1 ? "s" : "",
                   what);
    };
    if (disparity) {
      const msf::Calibration calibration = msf::loadCalibration(calib_path);
      const cv::Mat d = msf::depthToDisparity(depth, calibration);
      warnSaturated(d, "disparity");
      msf::writeKittiDisparityPng(files[1], d);
    } else if (colour) {
      msf::writeImage(files[1], msf::colorizeDepth(depth, static_cast<float>(range_min), static_cast<float>(range_max)));
    } else {
      warnSaturated(depth, "depth");
      msf::writeKittiDepthPng(files[1], depth);
    }
    msf::tool::printDone(tt.toc(), static_cast<std::size_t>(cv::countNonZero(depth)), "pixels with depth");
    return 0;
  });
}
