// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Paper step 2: compound interpolation of a projected LiDAR scan (or a baseline).
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/pinhole_camera.h>
#include <msf/io/velodyne_io.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/range_image/compound_interpolation.h>
#include <msf/range_image/ip_basic_completion.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/range_image/point_types.h>

#include <pcl/common/time.h>
#include <pcl/console/print.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

using DenseCloud = pcl::PointCloud<msf::PointXYZID>;

std::size_t countValid(const DenseCloud& cloud) {
  std::size_t n = 0;
  for (const auto& p : cloud)
    n += std::isfinite(p.z);
  return n;
}

/// What the command line sets.
struct Settings {
  std::string method_name = "compound", calib_path, image_size_text;
  msf::ProjectionConfig projection;
  msf::InterpolationConfig interpolation;
  msf::IpBasicConfig ip_basic;
  msf::RigAdaptationConfig rig;
  bool no_gaussian = false, canvas = false, overwrite = false;
};

/// The method and the calibration, if any; configure() sets the stages' configs for them.
struct Completion {
  msf::CompletionMethod method;
  std::optional<msf::Calibration> calibration;
};

Completion configure(Settings& settings) {
  msf::InterpolationConfig& interpolation = settings.interpolation;
  const msf::CompletionMethod method = msf::parseCompletionMethod(settings.method_name);
  const cv::Size image_size = msf::parseImageSize(settings.image_size_text);
  const std::optional<msf::Calibration> calibration =
      settings.calib_path.empty() ? std::nullopt
                                  : std::optional(msf::loadCalibration(settings.calib_path, image_size));
  if (calibration)
    msf::adaptToRig(interpolation, msf::rigAdaptation(settings.rig, *calibration));
  settings.projection.validate();
  if (settings.no_gaussian)
    interpolation.gaussian = false;
  if (method == msf::CompletionMethod::Linear)
    interpolation.slice.interpolant = msf::SliceInterpolant::Linear;
  else if (method == msf::CompletionMethod::Cubic)
    interpolation.slice.interpolant = msf::SliceInterpolant::Cubic;
  interpolation.validate();
  settings.ip_basic.variant = method == msf::CompletionMethod::IpBasicFast ? msf::IpBasicVariant::Fast
                                                                           : msf::IpBasicVariant::Multiscale;
  return {method, calibration};
}

/// A KITTI .bin scan or a .pcd cloud, with its done line.
pcl::PointCloud<pcl::PointXYZI>::Ptr loadInput(const std::string& path) {
  pcl::StopWatch watch;
  print_highlight("Loading ");
  print_value("%s ", path.c_str());
  pcl::PointCloud<pcl::PointXYZI>::Ptr input(new pcl::PointCloud<pcl::PointXYZI>);
  if (msf::fileExtension(path) == ".bin")
    msf::loadVelodyneBin(path, *input);
  else
    msf::loadCloud(path, *input);
  msf::tool::printDone(watch.getTime(), input->size(), "points");
  return input;
}

/// One of the filters over an organized cloud (CompoundInterpolation, IpBasicCompletion).
template <typename Filter, typename Config>
void filterWith(const Config& config, const msf::PinholeCamera& camera, const DenseCloud::Ptr& sparse,
                DenseCloud& dense) {
  Filter filter;
  filter.setConfig(config);
  filter.setCamera(camera);
  filter.setInputCloud(sparse);
  filter.filter(dense);
}

/// An organized cloud (msf_project's): its finite points are the real returns.
void completeOrganized(const pcl::PointCloud<pcl::PointXYZI>& input, const Completion& completion,
                       const Settings& settings, DenseCloud& dense) {
  DenseCloud::Ptr sparse(new DenseCloud);
  pcl::copyPointCloud(input, *sparse);
  for (auto& p : *sparse)
    p.distance = std::isfinite(p.z) ? 0.f : std::numeric_limits<float>::infinity();
  msf::PinholeCamera camera;
  if (completion.calibration)
    camera = msf::PinholeCamera::fromCalibration(*completion.calibration, settings.projection.camera);
  if (completion.method == msf::CompletionMethod::IpBasicFast ||
      completion.method == msf::CompletionMethod::IpBasicMultiscale)
    filterWith<msf::IpBasicCompletion<msf::PointXYZID>>(settings.ip_basic, camera, sparse, dense);
  else
    filterWith<msf::CompoundInterpolation<msf::PointXYZID>>(settings.interpolation, camera, sparse, dense);
}

int run(const msf::tool::Arguments& files, Settings& settings) {
  if (files.size() != 2)
    throw msf::InvalidInputError("expected <in.pcd> <out.pcd> (see -h)");
  const std::string in = files[0], out = files[1];
  const std::string in_ext = msf::fileExtension(in);
  if (in_ext != ".pcd" && in_ext != ".bin")
    throw msf::InvalidInputError("input '" + in + "' must be a .pcd cloud or a KITTI .bin scan");
  if (msf::fileExtension(out) != ".pcd")
    throw msf::InvalidInputError("output '" + out + "' must end in .pcd");
  msf::tool::requireNewOutputs({out}, settings.overwrite);
  const Completion completion = configure(settings);

  // A .bin is a scan; a .pcd is a scan when it is not organized.
  const pcl::PointCloud<pcl::PointXYZI>::Ptr input = loadInput(in);
  const bool is_scan = !input->isOrganized();

  DenseCloud dense;
  pcl::StopWatch watch;
  print_highlight("Interpolating ");
  print_info("(%s%s) ", msf::toString(completion.method), is_scan ? ", from the scan" : "");
  if (is_scan) {
    if (!completion.calibration)
      throw msf::InvalidInputError("'" + in + "' is a scan (not an organized cloud): give -calib to project it, "
                                   "or project it first with msf_project");
    msf::LidarCompletion lidar_completion(*completion.calibration, completion.method, settings.projection,
                                          settings.interpolation, settings.ip_basic);
    if (settings.canvas)
      lidar_completion.computeCanvas(*input, dense);
    else
      lidar_completion.compute(*input, dense);
  } else {
    if (settings.canvas)
      throw msf::InvalidInputError("-canvas needs a scan: '" + in + "' is an organized cloud, which has no margin");
    completeOrganized(*input, completion, settings, dense);
  }
  const std::size_t valid = countValid(dense);
  msf::tool::printDone(watch.getTime(), valid, "pixels with depth");
  // As msf_project: an empty or all-NaN input (or a scan none of whose returns lands in
  // the camera) is an error, not an empty cloud written with exit code 0.
  if (valid == 0)
    throw msf::InvalidInputError("no depth of '" + in + "' lands in the image" +
                                 (is_scan ? " of camera " + std::to_string(settings.projection.camera) +
                                                ": wrong calibration or scan?"
                                          : ": the cloud has no finite point"));

  watch.reset();
  print_highlight("Saving ");
  print_value("%s ", out.c_str());
  msf::saveCloud(out, dense);
  msf::tool::printDone(watch.getTime(), dense.size(), "points");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  Settings settings;
  msf::ProjectionConfig& projection = settings.projection;
  msf::InterpolationConfig& interpolation = settings.interpolation;
  msf::tool::CommandLine cli(
      "msf_interpolate", "<in.pcd> <out.pcd> [options]\n<scan.bin|scan.pcd> <out.pcd> -calib PATH [options]",
      "Densifies a sparse organized LiDAR cloud (msf_project's output) into an organized msf::PointXYZID cloud (x y "
      "z intensity distance): every pixel with an estimate is a point on its pixel's ray; `distance` is the distance "
      "in pixels to the nearest real return. Given a raw scan (.bin, or an unorganized .pcd) and -calib, it projects "
      "the scan itself, with the returns just outside the image (projection.margin_px) that bridge the gaps at the "
      "image's edges.");
  cli.value("-method", "NAME", settings.method_name,
            "compound (default, paper step 2) | linear | cubic | ipbasic | ipbasic_multiscale")
      .value("-config", "FILE",
             [&](const std::string& path) {
               const msf::ConfigFile file = msf::openConfigFile(path);
               file.read(projection);
               file.read(interpolation);
               file.read(settings.ip_basic);
               file.read(settings.rig);
             },
             "YAML config, sections interpolation, projection, ip_basic, rig (with -calib, the gaps in rows between "
             "LiDAR rings follow the rig's beams, as in msf_reconstruct)")
      .value("-calib", "PATH", settings.calib_path,
             "calibration: camera of the cloud (else recovered from its points); needed for a scan")
      .value("-rig", "FILE", settings.calib_path,
             "the same as -calib: a rig file (docs/usage.md, \"Your own rig\") or any calibration above")
      .value("-image_size", "WxH", settings.image_size_text, "image size where no image lies beside the calibration")
      .value("-camera", "N", projection.camera, "rectified camera 0..3 of -calib (default {default})")
      .value("-short_gap", "N", interpolation.slice.short_gap_px,
             "gaps of at most N empty pixels take the zero-slope cubic (interpolation.short_gap_px; KITTI's rows, "
             "scaled to the beams of -calib's rig as the config's are)")
      .value("-max_gap", "N", interpolation.slice.max_gap_px,
             "longer gaps stay empty (interpolation.max_gap_px; scaled as -short_gap)")
      .flag("-canvas", settings.canvas,
            "write the whole canvas, the image with its margin of projection.margin_px on every side: what the map "
            "takes around the fused image (msf_fuse then writes the frame msf_reconstruct integrates)")
      .flag("-no_gaussian", settings.no_gaussian,
            "no Gaussian hole filling after the slices (interpolation.gaussian: false)")
      .value("-threads", "N", interpolation.threads, "at most N threads of OpenCV's pool (0: all)")
      .overwriteOption(settings.overwrite);
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& files) { return run(files, settings); });
}
