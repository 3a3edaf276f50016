// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Paper steps 1-4 on numpy arrays, the stage objects the pipeline runs (modules/pipeline's
// Reconstructor::computeDepth): LiDAR projection and completion, SGBM stereo, per-pixel fusion, and
// the fused depth's colour. Each object keeps its work buffers from one call to the next.
#include "bindings.h"

#include <msf/fusion/depth_image_fusion.h>
#include <msf/io/pinhole_camera.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/range_image/lidar_completion.h>
#include <msf/range_image/real_returns.h>
#include <msf/stereo/color_sampler.h>
#include <msf/stereo/sgbm_stereo.h>

#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include <limits>
#include <mutex>
#include <string>

namespace msf::python {

namespace {

/// Steps 1-2: LidarCompletion, the scan projected onto the image grown by projection.margin_px
/// and completed (compound interpolation by default). Each stage takes `config` adapted to the
/// rig (adaptToRig), as the engine and the tools that run one stage do.
struct LidarStage {
  LidarStage(const Calibration& calibration, const PipelineConfig& config, const std::string& method)
      : LidarStage(calibration, adaptToRig(config, calibration), parseCompletionMethod(method)) {}
  LidarStage(const Calibration& calibration, const PipelineConfig& on_rig, CompletionMethod method)
      : completion(calibration, method, on_rig.projection, on_rig.interpolation) {}
  LidarCompletion completion;
  std::mutex mutex;
};

py::tuple computeLidarDepth(LidarStage& stage, const ArrayArg& scan) {
  const cv::Mat points = scanView(scan);
  cv::Mat depth, distance;
  withoutGil(stage.mutex, [&] {
    const auto cloud = scanFromPoints(points);
    stage.completion.computeDepth(*cloud, depth, &distance);
  });
  return py::make_tuple(toArray(depth), toArray(distance));
}

/// Step 3: SgbmStereo on the grey pair, narrowed by a depth prior and guided by real returns.
struct StereoStage {
  StereoStage(const Calibration& calibration, const PipelineConfig& config)
      : size(calibration.requireImageSize()) {
    matcher.setConfig(adaptToRig(config, calibration).stereo);
    matcher.setCalibration(calibration);
  }
  SgbmStereo matcher;
  cv::Size size;
  std::mutex mutex;
};

py::tuple computeStereoDepth(StereoStage& stage, const ArrayArg& left, const ArrayArg& right,
                             const ArrayArg& prior, const ArrayArg& guidance) {
  const cv::Mat l = imageView(left, "left", CV_8UC1, stage.size), r = imageView(right, "right", CV_8UC1, stage.size);
  const cv::Mat p = optionalImageView(prior, "prior", CV_32FC1, stage.size);
  const cv::Mat g = optionalImageView(guidance, "guidance", CV_32FC1, stage.size);
  cv::Mat depth, confidence;
  withoutGil(stage.mutex, [&] {
    stage.matcher.setInputImages(l, r);
    stage.matcher.setDepthPrior(p);
    stage.matcher.setGuidance(g);
    stage.matcher.computeDisparity();
    depth = stage.matcher.getDepth();
    confidence = stage.matcher.getConfidence(); // a new image each call
    stage.matcher.setInputImages(cv::Mat(), cv::Mat()); // holds no view of the caller's arrays
    stage.matcher.setDepthPrior(cv::Mat());
    stage.matcher.setGuidance(cv::Mat());
  });
  return py::make_tuple(toArray(depth), toArray(confidence));
}

/// Step 4: DepthImageFusion, the per-pixel fusion of the two depth images.
struct FusionStage {
  FusionStage(const Calibration& calibration, const PipelineConfig& config)
      : fusion(adaptToRig(config, calibration).fusion) {
    fusion.setCalibration(calibration);
  }
  DepthImageFusion fusion;
  std::mutex mutex;
};

py::tuple fuse(FusionStage& stage, const ArrayArg& lidar_depth, const ArrayArg& lidar_distance,
               const ArrayArg& stereo_depth, const ArrayArg& stereo_confidence, const ArrayArg& left,
               bool free_space, const ArrayArg& sky, bool fill_holes) {
  const cv::Mat ld = imageView(lidar_depth, "lidar_depth", CV_32FC1);
  const cv::Size size = ld.size();
  const cv::Mat dist = optionalImageView(lidar_distance, "lidar_distance", CV_32FC1, size);
  const cv::Mat sd = imageView(stereo_depth, "stereo_depth", CV_32FC1, size);
  const cv::Mat conf = optionalImageView(stereo_confidence, "stereo_confidence", CV_32FC1, size);
  const cv::Mat grey = optionalImageView(left, "left", CV_8UC1, size);
  // The sky's image: RGB (the library's order is BGR) or grey.
  const bool colour_sky = py::isinstance<py::array>(sky) && py::reinterpret_borrow<py::array>(sky).ndim() == 3;
  cv::Mat sky_image = optionalImageView(sky, "sky", colour_sky ? CV_8UC3 : CV_8UC1, size);
  if (colour_sky) { // into a new image: the caller's array stays as it was
    cv::Mat bgr;
    cv::cvtColor(sky_image, bgr, cv::COLOR_RGB2BGR);
    sky_image = bgr;
  }
  requireDepthValues(ld, "lidar_depth");
  requireDepthValues(sd, "stereo_depth");
  requireValuesIn(dist, "lidar_distance", 0.f, std::numeric_limits<float>::max(), false,
                  "a distance to the nearest real return, px, finite and not negative");
  requireValuesIn(conf, "stereo_confidence", 0.f, 1.f, false, "a confidence is 0..1");
  cv::Mat depth, weight, free_weight;
  withoutGil(stage.mutex, [&] {
    stage.fusion.setInputImage(grey);
    stage.fusion.setSkyImage(sky_image);
    stage.fusion.fuse(ld, dist, sd, conf, depth, &weight, &free_weight);
    if (fill_holes)
      stage.fusion.fillSmallHoles(depth, &weight, &free_weight);
    stage.fusion.setInputImage(cv::Mat());
    stage.fusion.setSkyImage(cv::Mat());
  });
  if (free_space)
    return py::make_tuple(toArray(depth), toArray(weight), toArray(free_weight));
  return py::make_tuple(toArray(depth), toArray(weight));
}

py::object colorize(const ArrayArg& depth, const Calibration& calibration, const ArrayArg& color,
                    const ArrayArg& fallback, int color_camera) {
  const cv::Mat d = imageView(depth, "depth", CV_32FC1, calibration.requireImageSize());
  const cv::Mat c = optionalImageView(color, "color", CV_8UC3);
  const bool rgb_fallback = py::isinstance<py::array>(fallback) && py::reinterpret_borrow<py::array>(fallback).ndim() == 3;
  const cv::Mat f = optionalImageView(fallback, "fallback", rgb_fallback ? CV_8UC3 : CV_8UC1, d.size());
  cv::Mat rgb;
  {
    py::gil_scoped_release release;
    const PinholeCamera camera = PinholeCamera::fromCalibration(calibration, 0);
    // The sampler copies a pixel's three bytes in order, so RGB in gives RGB out.
    const ColorSampler sampler = c.empty() ? ColorSampler() : ColorSampler(c, calibration, color_camera);
    colorizeDepth(d, camera, sampler, f.empty() ? cv::Mat(d.size(), CV_8UC1, cv::Scalar(0)) : f, rgb);
  }
  return toArray(rgb);
}

} // namespace

void bindStages(py::module_& m) {
  const PipelineConfig defaults;
  py::class_<LidarStage>(m, "LidarCompletion",
                         "Steps 1-2: a LiDAR scan projected into camera 0 (onto the image grown by "
                         "projection.margin_px) and completed to dense depth. Takes the sections projection and "
                         "interpolation of `config`, adapted to the rig as the engine adapts them.")
      .def(py::init<const Calibration&, const PipelineConfig&, const std::string&>(), py::arg("calibration"),
           py::arg("config") = defaults, py::arg("method") = "compound",
           "method: compound (the paper's), linear, cubic, ipbasic or ipbasic_multiscale.")
      .def("compute_depth", &computeLidarDepth, py::arg("scan"),
           "scan: (N, 4) float32 (or float64) x y z reflectance in the LiDAR's frame (a KITTI .bin), or (N, 3). "
           "Returns (depth, distance): (H, W) float32 metres (0 = none) and pixels to the nearest real return.")
      .def_property_readonly("camera", [](const LidarStage& s) { return s.completion.camera(); },
                             "The camera of the depth image.");

  py::class_<StereoStage>(m, "SgbmStereo",
                          "Step 3: semi-global matching on the rectified grey pair of cameras 0 and 1. Takes the "
                          "section stereo of `config`, adapted to the rig as the engine adapts it.")
      .def(py::init<const Calibration&, const PipelineConfig&>(), py::arg("calibration"), py::arg("config") = defaults)
      .def("compute_depth", &computeStereoDepth, py::arg("left"), py::arg("right"), py::arg("prior") = py::none(),
           py::arg("guidance") = py::none(),
           "left, right: (H, W) uint8 grey images. prior: (H, W) float32 depth (the interpolated LiDAR) that "
           "narrows the disparity search; guidance: (H, W) float32 sparse depth (real_returns of the LiDAR) "
           "that guides the matching when stereo.guidance is lidar. Returns (depth, confidence), (H, W) float32.");

  py::class_<FusionStage>(m, "DepthFusion",
                          "Step 4: the per-pixel fusion of the LiDAR's and the stereo depth. Takes the section "
                          "fusion of `config`, adapted to the rig as the engine adapts it.")
      .def(py::init<const Calibration&, const PipelineConfig&>(), py::arg("calibration"), py::arg("config") = defaults)
      .def("fuse", &fuse, py::arg("lidar_depth"), py::arg("lidar_distance"), py::arg("stereo_depth"),
           py::arg("stereo_confidence"), py::arg("left") = py::none(), py::arg("free_space") = false,
           py::arg("sky") = py::none(), py::arg("fill_holes") = false,
           "(H, W) float32 images: the LiDAR's depth and its distance to the nearest real return (None: all "
           "real), the stereo depth and its confidence (None: all 1). left: camera 0's grey image, for the "
           "facade extension and, near an edge, camera 0's own clear sky (as the pipeline does). sky: the "
           "image to find the open sky in, the colour camera's (H, W, 3) uint8 RGB or the (H, W) grey one: "
           "with fusion.clear_sky no depth in its clear (clipped or blue) sky, nor in its open sky in front "
           "of the column's LiDAR returns, nor at left's clipped pixels beside an edge that the texture keeps "
           "out of the mask, as the pipeline does. Returns (depth, weight), the weight the inverse "
           "variance in m^-2; with free_space=True also the weight of the free space in front of each depth. "
           "fill_holes=True: the small holes (fusion.hole_fill_px) take the nearest depth at weight 0, as in "
           "the engine's depth and msf_fuse's.");

  m.def("real_returns", [](const ArrayArg& depth, const ArrayArg& distance) {
    const cv::Mat d = imageView(depth, "depth", CV_32FC1);
    return toArray(realReturns(d, imageView(distance, "distance", CV_32FC1, d.size())));
  }, py::arg("depth"), py::arg("distance"),
        "The real LiDAR returns of an interpolated depth image: depth where distance is 0, else 0 (what "
        "guides SgbmStereo).");
  m.def("colorize_depth", &colorize, py::arg("depth"), py::arg("calibration"), py::arg("color"),
        py::arg("fallback") = py::none(), py::arg("color_camera") = 2,
        "The colour of each pixel of a depth image of camera 0, read in the colour camera's (H, W, 3) uint8 "
        "RGB image (the rectified cameras share one image size); pixels without depth or outside its view take "
        "`fallback` (camera 0's grey or RGB image; None: black). Returns (H, W, 3) uint8 RGB, what TsdfVolume.integrate takes as colour.");
}

} // namespace msf::python
