#include <msf/common/atomic_file.h>
#include <opencv2/core.hpp>
#include <msf/common/exceptions.h>
#include <msf/io/image_io.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>

namespace msf {

cv::Mat readImage(const std::string& path, int flags) {
  requireFile(path, "image");
  cv::Mat image = cv::imread(path, flags);
  if (image.empty())
    throw IOError("image '" + path + "' cannot be decoded");
  return image;
}

void writeImage(const std::string& path, const cv::Mat& image) {
  if (image.empty())
    throw InvalidInputError("cannot write '" + path + "': the image is empty");
  writeAtomically(path, [&](const std::string& tmp) {
    bool ok = false;
    try {
      ok = cv::imwrite(tmp, image);
    } catch (const cv::Exception& e) {
      throw IOError("cannot write image '" + path + "': " + e.err);
    }
    if (!ok)
      throw IOError("cannot write image '" + path + "'");
  });
}

namespace {

cv::Mat readScaled16(const std::string& path, const char* what) {
  const cv::Mat raw = readImage(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
  if (raw.type() != CV_16UC1)
    throw IOError(std::string(what) + " '" + path + "' is not a 16-bit single-channel PNG (value x 256)");
  cv::Mat out;
  raw.convertTo(out, CV_32F, 1.0 / 256.0);
  return out;
}

void writeScaled16(const std::string& path, const cv::Mat& values, const char* what) {
  if (values.type() != CV_32FC1)
    throw InvalidInputError(std::string("cannot write ") + what + " '" + path + "': expected a CV_32FC1 image");
  cv::Mat out(values.size(), CV_16UC1);
  for (int v = 0; v < values.rows; ++v) {
    const float* in = values.ptr<float>(v);
    auto* o = out.ptr<std::uint16_t>(v);
    for (int u = 0; u < values.cols; ++u) {
      const float x = in[u];
      // KITTI: 0 means no value, so tiny positives round up to the smallest step.
      o[u] = (std::isfinite(x) && x > 0.f)
                 ? static_cast<std::uint16_t>(std::clamp(std::lround(x * 256.0f), 1L, 65535L))
                 : 0;
    }
  }
  writeImage(path, out);
}

} // namespace

cv::Mat readKittiDepthPng(const std::string& path) { return readScaled16(path, "depth PNG"); }
cv::Mat readKittiDisparityPng(const std::string& path) { return readScaled16(path, "disparity PNG"); }
void writeKittiDepthPng(const std::string& path, const cv::Mat& depth) { writeScaled16(path, depth, "depth PNG"); }
void writeKittiDisparityPng(const std::string& path, const cv::Mat& disparity) {
  writeScaled16(path, disparity, "disparity PNG");
}

} // namespace msf
