// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <opencv2/core.hpp>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/io/image_io.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>

namespace msf {

namespace {
/// Width and height from a PNG's IHDR chunk, or {0, 0} when the file is not a PNG: the size
/// is checked before the decoder allocates it: a huge PNG would take gigabytes before the
/// matcher refused it.
cv::Size pngSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[24] = {};
  if (!in.read(reinterpret_cast<char*>(h), sizeof h))
    return {0, 0};
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (std::memcmp(h, kSignature, 8) != 0 || std::memcmp(h + 12, "IHDR", 4) != 0)
    return {0, 0};
  auto be32 = [&](int at) {
    return (std::uint32_t(h[at]) << 24) | (std::uint32_t(h[at + 1]) << 16) | (std::uint32_t(h[at + 2]) << 8) | h[at + 3];
  };
  const std::uint32_t w = be32(16), ht = be32(20);
  return {static_cast<int>(std::min<std::uint32_t>(w, INT_MAX)), static_cast<int>(std::min<std::uint32_t>(ht, INT_MAX))};
}
} // namespace

cv::Mat readImage(const std::string& path, int flags) {
  requireFile(path, "image");
  const cv::Size header = pngSize(path);
  if (header.width > 0 || header.height > 0)
    limits::checkImageSize(header.width, header.height, "image '" + path + "'");
  cv::Mat image;
  try {
    image = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    throw IOError("image '" + path + "' cannot be decoded: " + e.err);
  }
  if (image.empty())
    throw IOError("image '" + path + "' cannot be decoded");
  limits::checkImageSize(image.cols, image.rows, "image '" + path + "'");
  return image;
}

void writeImage(const std::string& path, const cv::Mat& image) {
  if (image.empty())
    throw InvalidInputError("cannot write '" + path + "': the image is empty");
  // Encoded in memory, then written checked (OpenCV's encoders do not check their writes).
  std::vector<uchar> bytes;
  bool ok = false;
  try {
    ok = cv::imencode(fileExtension(path), image, bytes);
  } catch (const cv::Exception& e) {
    throw IOError("cannot write image '" + path + "': " + e.err);
  }
  if (!ok)
    throw IOError("cannot write image '" + path + "'");
  writeBytesAtomically(path, bytes.data(), bytes.size());
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
      // KITTI: 0 means no value, so tiny positives round up to the smallest step; values
      // beyond the format's 65535 / 256 saturate (clamped before the cast: lround of 1e30 x
      // 256 is undefined, and gave 0.004).
      o[u] = (std::isfinite(x) && x > 0.f)
                 ? static_cast<std::uint16_t>(std::lround(std::clamp(x * 256.0f, 1.0f, 65535.0f)))
                 : 0;
    }
  }
  writeImage(path, out);
}

} // namespace

int significantBits(const cv::Mat& image) {
  if (image.depth() == CV_8U)
    return 8;
  if (image.depth() != CV_16U)
    throw InvalidInputError("an image of 8 or 16 bits a channel is needed, not OpenCV depth " +
                            std::to_string(image.depth()));
  double max_value = 0;
  cv::minMaxLoc(image.reshape(1), nullptr, &max_value);
  int bits = 8;
  while (bits < 16 && max_value > (1 << bits) - 1)
    ++bits;
  return bits;
}

int pairBits(const cv::Mat& left, const cv::Mat& right) {
  return std::max(significantBits(left), significantBits(right));
}

cv::Mat toEightBit(const cv::Mat& image, int bits) {
  if (image.depth() == CV_8U)
    return image;
  cv::Mat out;
  image.convertTo(out, CV_8U, 255.0 / ((1 << bits) - 1));
  return out;
}

cv::Mat readKittiDepthPng(const std::string& path) { return readScaled16(path, "depth PNG"); }
cv::Mat readKittiDisparityPng(const std::string& path) { return readScaled16(path, "disparity PNG"); }
void writeKittiDepthPng(const std::string& path, const cv::Mat& depth) { writeScaled16(path, depth, "depth PNG"); }
void writeKittiDisparityPng(const std::string& path, const cv::Mat& disparity) {
  writeScaled16(path, disparity, "disparity PNG");
}

} // namespace msf
