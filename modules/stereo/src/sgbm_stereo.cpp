// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/message_text.h>
#include <msf/common/parallel.h>
#include <msf/io/organized_conversion.h>
#include <msf/stereo/disparity_search_range.h>
#include <msf/stereo/guidance_hints.h>
#include <msf/stereo/impl/sgbm_stereo.hpp>
#include <msf/stereo/point_types.h>
#include <msf/stereo/stereo_confidence.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <iostream>
#include <mutex>
#include <string>

namespace msf {

namespace {

cv::Mat toGrey(const cv::Mat& image) {
  if (image.channels() == 1)
    return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}
} // namespace

void SgbmStereo::setConfig(const Config& config) {
  config.validate();
  config_ = config;
}

void SgbmStereo::setCalibration(const Calibration& calibration) {
  if (!(calibration.focalBaseline() > 0.0))
    throw CalibrationError("calibration '" + calibration.source +
                           "': the grey pair has no baseline (P1 must hold -f B in its last column)");
  calibration_ = calibration;
  has_calibration_ = true;
}

void SgbmStereo::setInputImages(const cv::Mat& left, const cv::Mat& right) {
  left_ = left;
  right_ = right;
}

void SgbmStereo::checkInputs() const {
  if (left_.empty())
    throw InvalidInputError("SgbmStereo: the left image is missing or empty");
  if (right_.empty())
    throw InvalidInputError("SgbmStereo: the right image is missing or empty");
  for (const auto* image : {&left_, &right_})
    if (image->depth() != CV_8U || (image->channels() != 1 && image->channels() != 3))
      throw InvalidInputError(std::string("SgbmStereo: the ") + (image == &left_ ? "left" : "right") +
                              " image must be 8-bit grey or BGR");
  if (left_.size() != right_.size())
    throw InvalidInputError("SgbmStereo: the left image is " + sizeText(left_) + " but the right image is " +
                            sizeText(right_));
  const cv::Size expected = calibration_.image_size;
  if (has_calibration_ && expected.width > 0 && left_.size() != expected)
    throw InvalidInputError("SgbmStereo: the images are " + sizeText(left_) + " but calibration '" +
                            calibration_.source + "' is " + std::to_string(expected.width) + "x" +
                            std::to_string(expected.height));
  if (!prior_.empty() && (prior_.type() != CV_32FC1 || prior_.size() != left_.size()))
    throw InvalidInputError("SgbmStereo: the depth prior must be CV_32FC1 of the images' size " + sizeText(left_) +
                            ", got " + sizeText(prior_));
  if (config_.lidarGuidance() && !guidance_.empty() &&
      (guidance_.type() != CV_32FC1 || guidance_.size() != left_.size()))
    throw InvalidInputError("SgbmStereo: the guidance (sparse depth) must be CV_32FC1 of the images' size " +
                            sizeText(left_) + ", got " + sizeText(guidance_) + " of type " +
                            std::to_string(guidance_.type()));
  if (config_.lidarGuidance() && !guidance_.empty() && !has_calibration_)
    throw CalibrationError("SgbmStereo: guidance needs the calibration (f B turns its depth into disparity)");
  // Without a prior the whole range is searched: a range as wide as the image leaves no
  // column with a match (0 points, and no word of why).
  if (prior_.empty() && config_.min_disparity_px + config_.num_disparities_px >= left_.cols)
    throw InvalidInputError("SgbmStereo: the disparity range (stereo.num_disparities_px, -num_disparities " +
                            std::to_string(config_.num_disparities_px) + ", from " +
                            std::to_string(config_.min_disparity_px) + ") is as wide as the images " +
                            sizeText(left_) + ": no column can be matched");
  if (config_.left_right_check && left_.cols <= config_.num_disparities_px)
    throw InvalidInputError("SgbmStereo: images " + sizeText(left_) + " are narrower than the disparity range");
}

bool SgbmStereo::nativeRuns(int width, const std::string& mode) const {
  if (!config_.nativeEngine())
    return false;
  if (width > SemiGlobalMatcher::maxWidth()) {
    static std::once_flag noted;
    std::call_once(noted, [] {
      std::cerr << "msf: note: stereo.engine native matches images up to " << SemiGlobalMatcher::maxWidth()
                << " px wide; wider ones run on OpenCV's StereoSGBM\n";
    });
    return false;
  }
  if (mode == "ground_3way")
    return true; // ours alone: where the CPU has no AVX2, the portable kernel gives the same result
  if (mode != "sgbm_3way" && mode != "sgbm") {
    static std::once_flag noted;
    std::call_once(noted, [&] {
      std::cerr << "msf: note: stereo.engine native implements modes ground_3way, sgbm_3way and sgbm; mode " << mode
                << " runs on OpenCV's StereoSGBM\n";
    });
    return false;
  }
  if (!SemiGlobalMatcher::usesAvx2()) {
    static std::once_flag noted;
    std::call_once(noted, [] {
      std::cerr << "msf: note: this CPU has no AVX2; OpenCV's StereoSGBM runs modes sgbm_3way and sgbm (the same "
                   "algorithm, faster there than the native portable kernel)\n";
    });
    return false;
  }
  return true;
}

void SgbmStereo::runMatcher(const cv::Mat& left, const cv::Mat& right, int num_disparities, const cv::Mat& hints,
                            cv::Mat& fixed) {
  const bool guided = !hints.empty();
  const std::string& mode = config_.modeFor(guided);
  if (nativeRuns(left.cols, mode)) {
    SemiGlobalMatcher::Params params;
    params.min_disparity = config_.min_disparity_px;
    params.num_disparities = num_disparities;
    params.block_size = config_.block_size_px;
    params.p1 = config_.resolvedP1();
    params.p2 = config_.resolvedP2();
    params.p1_rise = mode == "ground_3way" ? config_.resolvedP1Rise() : 0;
    params.pre_filter_cap = config_.pre_filter_cap;
    params.uniqueness_ratio = config_.uniqueness_ratio_pct;
    params.speckle_window_size = config_.speckle_window_size_px;
    params.speckle_range = config_.speckle_range_px;
    params.disp12_max_diff = config_.disp12_max_diff_px;
    params.diagonal_paths = mode == "sgbm";
    params.guidance_gain = config_.guidance_gain;
    params.guidance_max_penalty = config_.guidance_max_penalty;
    native_.setParams(params);
    native_.compute(left, right, fixed, hints);
    engine_used_ = "native";
    return;
  }
  if (mode == "ground_3way") {
    static std::once_flag noted;
    std::call_once(noted, [] {
      std::cerr << "msf: note: OpenCV's StereoSGBM has no ground_3way mode; its sgbm_3way runs\n";
    });
  }
  if (guided) {
    static std::once_flag noted;
    std::call_once(noted, [] {
      std::cerr << "msf: note: OpenCV's StereoSGBM runs instead of the native matcher and takes no guidance; "
                   "stereo.guidance is ignored\n";
    });
  }
  if (!matcher_)
    matcher_ = cv::StereoSGBM::create();
  matcher_->setMode(config_.opencvMode(guided));
  matcher_->setMinDisparity(config_.min_disparity_px);
  matcher_->setNumDisparities(num_disparities);
  matcher_->setBlockSize(config_.block_size_px);
  matcher_->setP1(config_.resolvedP1());
  matcher_->setP2(config_.resolvedP2());
  matcher_->setPreFilterCap(config_.pre_filter_cap);
  matcher_->setUniquenessRatio(config_.uniqueness_ratio_pct);
  matcher_->setSpeckleWindowSize(config_.speckle_window_size_px);
  matcher_->setSpeckleRange(config_.speckle_range_px);
  matcher_->setDisp12MaxDiff(config_.disp12_max_diff_px);
  matcher_->compute(left, right, fixed);
  engine_used_ = "opencv";
}

cv::Mat SgbmStereo::match(const cv::Mat& left, const cv::Mat& right, int num_disparities, const cv::Mat& hints) {
  cv::Mat fixed; // CV_16S, disparity x 16
  const int border = config_.match_left_border ? std::max(0, config_.min_disparity_px + num_disparities) : 0;
  if (border == 0) {
    runMatcher(left, right, num_disparities, hints, fixed);
    return fixed;
  }
  cv::Mat left_padded, right_padded, hints_padded;
  cv::copyMakeBorder(left, left_padded, 0, 0, border, 0, cv::BORDER_REPLICATE);
  cv::copyMakeBorder(right, right_padded, 0, 0, border, 0, cv::BORDER_REPLICATE);
  if (!hints.empty())
    cv::copyMakeBorder(hints, hints_padded, 0, 0, border, 0, cv::BORDER_CONSTANT, cv::Scalar(0));
  runMatcher(left_padded, right_padded, num_disparities, hints_padded, fixed);
  return fixed.colRange(border, border + left.cols);
}

void SgbmStereo::computeDisparity() {
  checkInputs();
  const cv::Mat left = toGrey(left_), right = toGrey(right_);

  int num_disparities = config_.num_disparities_px;
  if (config_.prior_search_range && !prior_.empty() && has_calibration_)
    num_disparities = searchRangeFromDepth(prior_, calibration_.focalBaseline(), config_.min_disparity_px,
                                           config_.prior_margin_px, config_.num_disparities_px);
  searched_disparities_ = num_disparities;

  const cv::Mat hints = config_.lidarGuidance() && !guidance_.empty()
                            ? guidanceHints(guidance_, calibration_.focalBaseline(), config_.guidance_bridge_rows,
                                            config_.guidance_bridge_agreement)
                            : cv::Mat();
  const cv::Mat fixed = match(left, right, num_disparities, hints);
  cv::Mat fixed_right; // disparities of the right view, in right-image columns
  if (config_.left_right_check) {
    // A right-view match is the left-view match of the mirrored pair, mirrored back.
    cv::Mat left_flipped, right_flipped;
    cv::flip(left, left_flipped, 1);
    cv::flip(right, right_flipped, 1);
    cv::flip(match(right_flipped, left_flipped, num_disparities, hints.empty() ? hints : rightViewHintsMirrored(hints)),
             fixed_right, 1);
  }

  const int rows = fixed.rows, cols = fixed.cols;
  const float max_depth = config_.max_depth_m;
  const float min_disparity = (max_depth > 0.f && has_calibration_)
                                  ? static_cast<float>(calibration_.focalBaseline()) / max_depth
                                  : 0.f;
  const float lr_max = config_.left_right_max_diff_px;
  disparity_.create(rows, cols, CV_32FC1);
  parallelFor(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      const short* in = fixed.ptr<short>(v);
      const short* in_right = fixed_right.empty() ? nullptr : fixed_right.ptr<short>(v);
      float* out = disparity_.ptr<float>(v);
      // Branch-free, so that it runs in vectors; the explicit left-right check, rarely on,
      // follows in a second loop.
      for (int u = 0; u < cols; ++u) {
        // OpenCV marks a pixel without a match with (min_disparity - 1) * 16; d <= 0 has no
        // depth, nor has one too far or matched in the replicated border left of the right image.
        const float d = static_cast<float>(in[u]) * (1.f / 16.f);
        const bool kept = (d > 0.f) & (d >= min_disparity) & (d <= static_cast<float>(u));
        out[u] = kept ? d : 0.f;
      }
      if (!in_right)
        continue;
      for (int u = 0; u < cols; ++u) {
        const float d = out[u];
        if (!(d > 0.f))
          continue;
        const int ur = static_cast<int>(std::lround(static_cast<float>(u) - d));
        const float dr = ur >= 0 && ur < cols ? static_cast<float>(in_right[ur]) * (1.f / 16.f) : -1.f;
        if (!(dr > 0.f) || std::fabs(dr - d) > lr_max)
          out[u] = 0.f;
      }
    }
  });
  confidence_ = stereoConfidence(disparity_, config_.confidence);
}

cv::Mat SgbmStereo::getDepth() const {
  if (!has_calibration_)
    throw CalibrationError("SgbmStereo: no calibration set (setCalibration)");
  if (disparity_.empty())
    return cv::Mat();
  return disparityToDepth(disparity_, calibration_);
}

#define MSF_INSTANTIATE_SGBM_STEREO(T) template void SgbmStereo::compute<T>(pcl::PointCloud<T>&);
MSF_INSTANTIATE_SGBM_STEREO(pcl::PointXYZ)
MSF_INSTANTIATE_SGBM_STEREO(pcl::PointXYZRGB)
MSF_INSTANTIATE_SGBM_STEREO(pcl::PointXYZRGBA)
MSF_INSTANTIATE_SGBM_STEREO(msf::PointXYZRGBConfidence)

} // namespace msf
