// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/range_image/ip_basic.h>

#include <opencv2/imgproc.hpp>
#include <ostream>

namespace msf {

IpBasicVariant parseIpBasicVariant(const std::string& name) {
  if (const auto variant = choiceOf(kIpBasicVariants, name))
    return *variant;
  throw ConfigError("ip_basic.variant '" + name + "' is not " + wordList(kIpBasicVariants));
}

IpBasicBlur parseIpBasicBlur(const std::string& name) {
  if (const auto blur = choiceOf(kIpBasicBlurs, name))
    return *blur;
  throw ConfigError("ip_basic.blur '" + name + "' is not " + wordList(kIpBasicBlurs));
}

const char* toString(IpBasicVariant variant) { return wordOf(kIpBasicVariants, variant); }

const char* toString(IpBasicBlur blur) { return wordOf(kIpBasicBlurs, blur); }

void IpBasicConfig::validate() const { checkKeyRanges(*this); }

namespace {

cv::Mat kernel(std::initializer_list<std::initializer_list<int>> rows) {
  cv::Mat k(static_cast<int>(rows.size()), static_cast<int>(rows.begin()->size()), CV_8UC1);
  int r = 0;
  for (const auto& row : rows) {
    int c = 0;
    for (int v : row)
      k.at<std::uint8_t>(r, c++) = static_cast<std::uint8_t>(v);
    ++r;
  }
  return k;
}

cv::Mat full(int n) { return cv::Mat::ones(n, n, CV_8UC1); }

cv::Mat cross(int n) {
  cv::Mat k = cv::Mat::zeros(n, n, CV_8UC1);
  k.row(n / 2).setTo(1);
  k.col(n / 2).setTo(1);
  return k;
}

const cv::Mat& diamond5() {
  static const cv::Mat k = kernel({{0, 0, 1, 0, 0}, {0, 1, 1, 1, 0}, {1, 1, 1, 1, 1}, {0, 1, 1, 1, 0}, {0, 0, 1, 0, 0}});
  return k;
}

cv::Mat above(const cv::Mat& m, float t) { return m > t; }
cv::Mat below(const cv::Mat& m, float t) { return m < t; }

/// max_depth - d where d > 0.1, in place.
void invert(cv::Mat& d, float max_depth) {
  const cv::Mat valid = above(d, 0.1f);
  cv::Mat inverted = max_depth - d;
  inverted.copyTo(d, valid);
}

/// Per column, false above the first pixel > 0.1 (true everywhere in an empty column).
cv::Mat topMask(const cv::Mat& d) {
  cv::Mat mask(d.size(), CV_8UC1, cv::Scalar(255));
  for (int c = 0; c < d.cols; ++c) {
    int top = 0;
    while (top < d.rows && !(d.at<float>(top, c) > 0.1f))
      ++top;
    if (top == d.rows)
      top = 0; // numpy's argmax of an all-false column
    for (int r = 0; r < top; ++r)
      mask.at<std::uint8_t>(r, c) = 0;
  }
  return mask;
}

/// Copies each column's top pixel > 0.1 to the rows above it.
void extendTop(cv::Mat& d) {
  for (int c = 0; c < d.cols; ++c) {
    int top = 0;
    while (top < d.rows && !(d.at<float>(top, c) > 0.1f))
      ++top;
    if (top == d.rows)
      continue;
    for (int r = 0; r < top; ++r)
      d.at<float>(r, c) = d.at<float>(top, c);
  }
}

cv::Mat fast(cv::Mat d, const IpBasicConfig& config) {
  invert(d, config.max_depth_m);
  cv::dilate(d, d, diamond5());
  cv::morphologyEx(d, d, cv::MORPH_CLOSE, full(5));
  cv::Mat dilated;
  cv::dilate(d, dilated, full(7));
  dilated.copyTo(d, below(d, 0.1f));
  if (config.extrapolate) {
    extendTop(d);
    cv::dilate(d, dilated, full(31));
    dilated.copyTo(d, below(d, 0.1f));
  }
  cv::medianBlur(d, d, 5);
  if (config.blur == IpBasicBlur::Bilateral) {
    cv::Mat blurred;
    cv::bilateralFilter(d, blurred, 5, 1.5, 2.0);
    d = blurred;
  } else if (config.blur == IpBasicBlur::Gaussian) {
    cv::Mat blurred;
    cv::GaussianBlur(d, blurred, cv::Size(5, 5), 0);
    blurred.copyTo(d, above(d, 0.1f));
  }
  invert(d, config.max_depth_m);
  return d;
}

cv::Mat multiscale(const cv::Mat& in, const IpBasicConfig& config) {
  // Bins by depth before inversion: near dilates most.
  const cv::Mat near = above(in, 0.1f) & (in <= 15.f);
  const cv::Mat med = above(in, 15.f) & (in <= 30.f);
  const cv::Mat far = above(in, 30.f);
  cv::Mat s1 = in.clone();
  invert(s1, config.max_depth_m);

  auto binDilate = [&](const cv::Mat& bin, const cv::Mat& k) {
    cv::Mat masked = cv::Mat::zeros(s1.size(), CV_32FC1), out;
    s1.copyTo(masked, bin);
    cv::dilate(masked, out, k);
    return out;
  };
  const cv::Mat d_far = binDilate(far, cross(3)), d_med = binDilate(med, cross(5)), d_near = binDilate(near, cross(7));
  cv::Mat s2 = s1.clone();
  d_far.copyTo(s2, above(d_far, 0.1f));
  d_med.copyTo(s2, above(d_med, 0.1f));
  d_near.copyTo(s2, above(d_near, 0.1f));

  cv::Mat s3;
  cv::morphologyEx(s2, s3, cv::MORPH_CLOSE, full(5));

  cv::Mat s4 = s3.clone(), blurred;
  cv::medianBlur(s3, blurred, 5);
  blurred.copyTo(s4, above(s3, 0.1f));

  cv::Mat top = topMask(s4);
  const cv::Mat empty = ~above(s4, 0.1f) & top;
  cv::Mat dilated;
  cv::dilate(s4, dilated, full(9));
  cv::Mat s5 = s4.clone();
  dilated.copyTo(s5, empty);

  cv::Mat s6 = s5.clone();
  if (config.extrapolate) {
    extendTop(s6);
    top = cv::Mat(s5.size(), CV_8UC1, cv::Scalar(255));
  } else {
    top = topMask(s5);
  }

  cv::Mat s7 = s6.clone();
  for (int i = 0; i < 6; ++i) {
    const cv::Mat holes = below(s7, 0.1f) & top;
    cv::dilate(s7, dilated, full(5));
    dilated.copyTo(s7, holes);
  }
  cv::medianBlur(s7, blurred, 5);
  const cv::Mat valid = above(s7, 0.1f) & top;
  blurred.copyTo(s7, valid);
  if (config.blur == IpBasicBlur::Gaussian) {
    cv::GaussianBlur(s7, blurred, cv::Size(5, 5), 0);
    blurred.copyTo(s7, above(s7, 0.1f) & top);
  } else if (config.blur == IpBasicBlur::Bilateral) {
    cv::bilateralFilter(s7, blurred, 5, 0.5, 2.0);
    blurred.copyTo(s7, valid);
  }
  invert(s7, config.max_depth_m);
  return s7;
}

} // namespace

cv::Mat ipBasic(const cv::Mat& sparse, const IpBasicConfig& config) {
  config.validate();
  if (sparse.type() != CV_32FC1 || sparse.empty())
    throw InvalidInputError("ip_basic: expected a non-empty CV_32FC1 depth image");
  cv::Mat d = sparse.clone();
  cv::patchNaNs(d, 0.0);
  d = config.variant == IpBasicVariant::Fast ? fast(d, config) : multiscale(d, config);
  // What stays <= 0.1 (including negatives from depths beyond max_depth) has no estimate.
  d.setTo(0.f, ~above(d, 0.1f));
  return d;
}

} // namespace msf
