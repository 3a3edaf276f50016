// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The KITTI 2015 devkit's disparity evaluation of one estimate: D1 (3 px and 5 %) for
// background, foreground and all pixels, the paper's eq. 8 mean absolute error, density.
// Given two folders, every frame of the estimate folder against its ground truth, summed
// over the pixels of all frames (a synthetic sequence's gt/disp_0, split by gt/obj_map_0).
// With -confidence, also the error by the matcher's confidence beside the fusion's sigma model.
#include <msf/common/atomic_file.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/evaluation/confidence_calibration.h>
#include <msf/evaluation/disparity_metrics.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/point_types.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace {

void printRow(const char* name, const msf::DisparityRegionErrors& r) {
  std::printf("%-11s %8.2f %%  %8.2f %%  %8.2f %%  %8.3f  %9zu  %9zu\n", name, 100.0 * r.d1(), 100.0 * r.d1Estimated(),
              100.0 * r.density(), r.meanAbsError(), r.bad, r.gt_pixels);
}

/// The confidence field of an organized cloud (msf_stereo's output) as an image of `size`.
cv::Mat readConfidence(const std::string& path, const cv::Size& size) {
  pcl::PointCloud<msf::PointXYZRGBConfidence> cloud;
  msf::loadCloud(path, cloud);
  if (static_cast<int>(cloud.width) != size.width || static_cast<int>(cloud.height) != size.height)
    throw msf::InvalidInputError("confidence cloud '" + path + "' is " + std::to_string(cloud.width) + "x" +
                                 std::to_string(cloud.height) + " but the ground truth is " +
                                 std::to_string(size.width) + "x" + std::to_string(size.height) +
                                 " (it must be the organized cloud of the estimate, as msf_stereo writes)");
  cv::Mat confidence(size, CV_32FC1);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      confidence.at<float>(v, u) = cloud(u, v).confidence;
  return confidence;
}

/// One frame: the disparities and, when `obj_map_path` is not empty, the object map; with a
/// `confidence_path`, its pixels also go into `calibration`.
msf::DisparityEvaluation evaluateFiles(const std::string& gt_path, const std::string& est_path,
                                       const std::string& obj_map_path, const msf::DisparityEvalOptions& options,
                                       const std::string& confidence_path, msf::ConfidenceCalibration& calibration) {
  const cv::Mat gt = msf::readKittiDisparityPng(gt_path);
  const cv::Mat est = msf::readKittiDisparityPng(est_path);
  if (est.size() != gt.size())
    throw msf::InvalidInputError("estimate '" + est_path + "' is " + std::to_string(est.cols) + "x" +
                                 std::to_string(est.rows) + " but ground truth '" + gt_path + "' is " +
                                 std::to_string(gt.cols) + "x" + std::to_string(gt.rows));
  cv::Mat obj_map;
  if (!obj_map_path.empty()) {
    obj_map = msf::readImage(obj_map_path, cv::IMREAD_UNCHANGED);
    if (obj_map.channels() != 1)
      throw msf::InvalidInputError("object map '" + obj_map_path + "' must be a single-channel image");
    if (obj_map.size() != gt.size())
      throw msf::InvalidInputError("object map '" + obj_map_path + "' is " + std::to_string(obj_map.cols) + "x" +
                                   std::to_string(obj_map.rows) + " but ground truth '" + gt_path + "' is " +
                                   std::to_string(gt.cols) + "x" + std::to_string(gt.rows));
  }
  const msf::DisparityEvaluation e = msf::evaluateDisparity(gt, est, obj_map, options);
  if (!confidence_path.empty())
    calibration.add(gt, est, readConfidence(confidence_path, gt.size()));
  // A ground truth without a valid pixel scores nothing: D1 0.00 % would read as perfect.
  if (e.all.gt_pixels == 0)
    throw msf::InvalidInputError("ground truth '" + gt_path + "' has no valid pixel (every disparity is 0)");
  return e;
}

/// The error by confidence: measured (robust sigma, the outliers beyond the D1 threshold
/// apart) against the fusion's sigma for that confidence.
void printCalibration(const msf::ConfidenceCalibration& calibration, const msf::DepthFusionConfig& model,
                      float outlier_px) {
  if (calibration.pixels() == 0)
    throw msf::InvalidInputError("-confidence: no pixel has a ground truth, an estimate and a confidence");
  std::printf("\nerror by stereo confidence (the fusion's sigma: %g px at confidence 1, %g px at 0)\n",
              model.stereo_sigma_min_px, model.stereo_sigma_max_px);
  const std::string beyond = "> " + msf::configValue(outlier_px) + " px";
  std::printf("%-11s %9s  %9s  %9s  %12s  %8s  %12s  %9s\n", "confidence", "pixels", "mean conf", "median px",
              "robust sd px", beyond.c_str(), "model sd px", "sd/model");
  for (const auto& r : calibration.rows(model, outlier_px)) {
    if (r.pixels == 0) {
      std::printf("%4.2f-%4.2f  %9zu\n", r.lo, r.hi, r.pixels);
      continue;
    }
    std::printf("%4.2f-%4.2f  %9zu  %9.3f  %+9.3f  %12.3f  %6.2f %%  %12.3f  %9.2f\n", r.lo, r.hi, r.pixels,
                r.mean_confidence, r.median_px, r.robust_sigma_px, 100.0 * r.outlier_share, r.model_sigma_px,
                r.robust_sigma_px / r.model_sigma_px);
  }
  std::printf("(robust sd: 1.4826 x the median absolute deviation of estimate - truth; %s: the share of errors "
              "beyond -abs_px)\n", beyond.c_str());
}

bool isDirectory(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_directory(path, ec);
}

/// The object-map folder beside a ground-truth disparity folder, "" when there is none.
std::string siblingObjectMapDir(const std::string& gt_dir) {
  namespace fs = std::filesystem;
  fs::path p = fs::absolute(gt_dir).lexically_normal();
  if (p.filename().empty())
    p = p.parent_path();
  for (const char* name : {"obj_map_0", "obj_map"})
    if (isDirectory((p.parent_path() / name).string()))
      return (p.parent_path() / name).string();
  return "";
}

/// Folder mode: every *.png of est_dir against gt_dir (and obj_map_dir, confidence_dir when
/// not empty: NNNNNN.png and NNNNNN.pcd).
msf::DisparityEvaluation evaluateFolders(const std::string& gt_dir, const std::string& est_dir,
                                         const std::string& obj_map_dir, const msf::DisparityEvalOptions& options,
                                         const std::string& confidence_dir, msf::ConfidenceCalibration& calibration,
                                         std::size_t& frames) {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  for (const std::string& path : msf::filesIn(est_dir, {".png"}, "estimate folder"))
    names.push_back(fs::path(path).filename().string());
  msf::DisparityEvaluation sum;
  for (const auto& name : names) {
    const std::string gt_path = (fs::path(gt_dir) / name).string();
    const std::string est_path = (fs::path(est_dir) / name).string();
    if (!fs::is_regular_file(gt_path))
      throw msf::InvalidInputError("ground truth '" + gt_path + "' for estimate '" + est_path + "' does not exist");
    std::string obj_map_path;
    if (!obj_map_dir.empty()) {
      obj_map_path = (fs::path(obj_map_dir) / name).string();
      if (!fs::is_regular_file(obj_map_path))
        throw msf::InvalidInputError("object map '" + obj_map_path + "' for estimate '" + est_path +
                                     "' does not exist");
    }
    std::string confidence_path;
    if (!confidence_dir.empty()) {
      confidence_path = (fs::path(confidence_dir) / fs::path(name).replace_extension(".pcd")).string();
      if (!fs::is_regular_file(confidence_path))
        throw msf::InvalidInputError("confidence cloud '" + confidence_path + "' for estimate '" + est_path +
                                     "' does not exist");
    }
    sum += evaluateFiles(gt_path, est_path, obj_map_path, options, confidence_path, calibration);
  }
  frames = names.size();
  return sum;
}

} // namespace

int main(int argc, char** argv) {
  msf::DisparityEvalOptions options;
  std::string obj_map_path, obj_map_dir, confidence;
  msf::DepthFusionConfig model;
  bool config_given = false;
  msf::tool::CommandLine cli(
      "msf_eval_disparity", "<gt.png> <est.png> [options]\n<gt_dir> <est_dir> [options]",
      "KITTI 16-bit disparity PNGs (pixels x 256, 0 = none): D1 outliers (error > 3 px and > 5 %), mean absolute "
      "error (eq. 8) and density, per region when an object map is given. With folders: every NNNNNN.png of est_dir "
      "against gt_dir/NNNNNN.png (a missing one is an error), the pixels of all frames summed into one table. The "
      "object maps come from a sibling folder of gt_dir named obj_map_0 (synthetic gt/disp_0) or obj_map (KITTI 2015 "
      "disp_*), or -obj_map_dir.");
  cli.value("-obj_map", "PATH", obj_map_path, "object map (0 = background, else foreground), e.g. KITTI obj_map/*.png")
      .value("-obj_map_dir", "DIR", obj_map_dir, "folder mode: object maps DIR/NNNNNN.png")
      .flag("-interpolate", options.interpolate_background,
            "fill missing estimates as the devkit does (background interpolation); without it a missing estimate "
            "counts as bad in D1")
      .value("-abs_px", "X", options.abs_threshold_px, "absolute threshold in pixels (default {default})")
      .value("-rel", "X", options.rel_threshold, "relative threshold (default {default})")
      .value("-confidence", "PATH", confidence,
             "the estimate's confidence: msf_stereo's output cloud (field confidence), or with folders a folder of "
             "NNNNNN.pcd; adds the error by confidence beside the sigma the fusion assumes for it")
      .value("-config", "FILE",
             [&](const std::string& path) {
               msf::readConfigSection(path, model);
               config_given = true;
             },
             "YAML config, section fusion: the sigma model of -confidence (stereo_sigma_min_px, stereo_sigma_max_px)");
  return cli.run(argc, argv, 2, [&](const msf::tool::Arguments& files) {
    if (files.size() != 2)
      throw msf::InvalidInputError("expected <gt.png> <est.png> or <gt_dir> <est_dir> (see -h)");
    if (!(options.abs_threshold_px >= 0.f) || !(options.rel_threshold >= 0.f))
      throw msf::InvalidInputError("-abs_px and -rel must be >= 0");

    const bool folders = isDirectory(files[0]);
    if (folders != isDirectory(files[1]))
      throw msf::InvalidInputError("'" + files[0] + "' and '" + files[1] +
                                   "' must both be PNG files or both be folders");
    if (config_given && confidence.empty())
      throw msf::InvalidInputError("-config gives the sigma model of -confidence, which is not given");
    if (!confidence.empty() && folders != isDirectory(confidence))
      throw msf::InvalidInputError("-confidence '" + confidence + "' must be " +
                                   (folders ? "a folder of NNNNNN.pcd, as the estimates are folders"
                                            : "a .pcd file, as the estimate is one frame"));
    std::size_t frames = 1;
    msf::ConfidenceCalibration calibration;
    msf::DisparityEvaluation e;
    if (folders) {
      if (!obj_map_path.empty())
        throw msf::InvalidInputError("-obj_map is for one frame; with folders use -obj_map_dir");
      if (obj_map_dir.empty())
        obj_map_dir = siblingObjectMapDir(files[0]);
      else if (!isDirectory(obj_map_dir))
        throw msf::InvalidInputError("-obj_map_dir '" + obj_map_dir + "' is not a folder");
      e = evaluateFolders(files[0], files[1], obj_map_dir, options, confidence, calibration, frames);
    } else {
      if (!obj_map_dir.empty())
        throw msf::InvalidInputError("-obj_map_dir is for folders; with one frame use -obj_map");
      e = evaluateFiles(files[0], files[1], obj_map_path, options, confidence, calibration);
    }

    if (folders)
      std::printf("%zu frames of '%s'%s\n", frames, files[1].c_str(),
                  obj_map_dir.empty() ? "" : (", object maps '" + obj_map_dir + "'").c_str());
    std::printf("%-11s %10s  %10s  %10s  %8s  %9s  %9s\n", "region", "D1", "D1 (est.)", "density", "MAE px",
                "bad", "gt pixels");
    if (e.has_object_map) {
      printRow("background", e.background);
      printRow("foreground", e.foreground);
    }
    printRow("all", e.all);
    std::printf("(D1: error > %g px and > %g %% of the true disparity; %s)\n", options.abs_threshold_px,
                100.0 * options.rel_threshold,
                options.interpolate_background ? "missing estimates interpolated as the devkit"
                                               : "missing estimates count as bad");
    if (!confidence.empty())
      printCalibration(calibration, model, options.abs_threshold_px);
    return 0;
  });
}
