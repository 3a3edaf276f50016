// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/impl/pinhole_camera.hpp>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>

#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace msf {

PinholeCamera PinholeCamera::fromCalibration(const Calibration& calibration, int camera) {
  Calibration::checkCamera(camera);
  const cv::Size size = calibration.requireImageSize();
  // Pixel indices (v * width + u, with a margin) are ints: the size is bounded first.
  limits::checkImageSize(size.width, size.height, "calibration '" + calibration.source + "'");
  PinholeCamera c;
  c.fx = static_cast<float>(calibration.fx(camera));
  c.fy = static_cast<float>(calibration.fy(camera));
  c.cx = static_cast<float>(calibration.cx(camera));
  c.cy = static_cast<float>(calibration.cy(camera));
  c.width = size.width;
  c.height = size.height;
  if (!(c.fx > 0.f && c.fy > 0.f) || !std::isfinite(c.fx) || !std::isfinite(c.fy) || !std::isfinite(c.cx) ||
      !std::isfinite(c.cy))
    throw CalibrationError("calibration '" + calibration.source + "': camera " + std::to_string(camera) +
                           " has a focal length that is not > 0 and finite, or a NaN centre");
  return c;
}

std::string PinholeCamera::intrinsicsText() const {
  char text[96];
  std::snprintf(text, sizeof text, "fx %.2f, fy %.2f, cx %.2f, cy %.2f", fx, fy, cx, cy);
  return text;
}

PinholeCamera PinholeCamera::onCanvas(const cv::Rect& image_in_canvas, const cv::Size& canvas) const {
  PinholeCamera c = *this;
  c.cx += static_cast<float>(image_in_canvas.x);
  c.cy += static_cast<float>(image_in_canvas.y);
  c.width = canvas.width;
  c.height = canvas.height;
  return c;
}

cv::Rect imageInCanvas(const cv::Size& canvas, const cv::Size& image, const std::string& what) {
  if (canvas == image)
    return {};
  const int margin_x = (canvas.width - image.width) / 2, margin_y = (canvas.height - image.height) / 2;
  if (margin_x <= 0 || margin_y <= 0 || canvas.width != image.width + 2 * margin_x ||
      canvas.height != image.height + 2 * margin_y)
    throw InvalidInputError(what + " is " + std::to_string(canvas.width) + "x" + std::to_string(canvas.height) +
                            ": neither the image's " + std::to_string(image.width) + "x" +
                            std::to_string(image.height) + " nor that image with a margin on every side");
  return {margin_x, margin_y, image.width, image.height};
}

void PinholeFit::add(double u, double v, double x, double y, double z) {
  const double a = x / z, b = y / z;
  n_ += 1;
  sa_ += a, saa_ += a * a, su_ += u, sau_ += a * u, suu_ += u * u;
  sb_ += b, sbb_ += b * b, sv_ += v, sbv_ += b * v, svv_ += v * v;
}

void PinholeFit::merge(const PinholeFit& o) {
  n_ += o.n_;
  sa_ += o.sa_, saa_ += o.saa_, su_ += o.su_, sau_ += o.sau_, suu_ += o.suu_;
  sb_ += o.sb_, sbb_ += o.sbb_, sv_ += o.sv_, sbv_ += o.sbv_, svv_ += o.svv_;
}

PinholeCamera PinholeFit::solve(int width, int height, const std::string& what, double max_rms_px) const {
  const double du = n_ * saa_ - sa_ * sa_, dv = n_ * sbb_ - sb_ * sb_;
  if (n_ < 10 || !(du > 1e-12 * n_ * n_) || !(dv > 1e-12 * n_ * n_))
    throw InvalidInputError(what + " has too few valid points (" + std::to_string(static_cast<long long>(n_)) +
                            ") spread over the image to recover its camera; give the calibration");
  const double fx = (n_ * sau_ - sa_ * su_) / du, cx = (su_ - fx * sa_) / n_;
  const double fy = (n_ * sbv_ - sb_ * sv_) / dv, cy = (sv_ - fy * sb_) / n_;
  // Residual sums of squares of the two line fits, expanded from the sums.
  const double ru = suu_ - 2 * fx * sau_ - 2 * cx * su_ + fx * fx * saa_ + 2 * fx * cx * sa_ + n_ * cx * cx;
  const double rv = svv_ - 2 * fy * sbv_ - 2 * cy * sv_ + fy * fy * sbb_ + 2 * fy * cy * sb_ + n_ * cy * cy;
  const double rms = std::sqrt(std::max(0.0, std::max(ru, rv)) / n_);
  if (!(fx > 0) || !(fy > 0) || !(rms <= max_rms_px))
    throw InvalidInputError(what + " is not a camera image: its points do not lie on their pixels' rays (fit residual " +
                            std::to_string(rms) + " px); give the calibration");
  PinholeCamera c;
  c.fx = static_cast<float>(fx);
  c.fy = static_cast<float>(fy);
  c.cx = static_cast<float>(cx);
  c.cy = static_cast<float>(cy);
  c.width = width;
  c.height = height;
  return c;
}

void requireCameraOfPoints(const PinholeFit& fit, const PinholeCamera& camera, const std::string& what,
                           const std::string& source) {
  PinholeCamera points;
  try {
    points = fit.solve(camera.width, camera.height, what);
  } catch (const InvalidInputError&) {
    return;
  }
  constexpr double kMostApartPx = 2.0;
  double apart = 0;
  for (const double u : {0.0, camera.width - 1.0})
    apart = std::max(apart, std::abs((u - points.cx) / points.fx * camera.fx + camera.cx - u));
  for (const double v : {0.0, camera.height - 1.0})
    apart = std::max(apart, std::abs((v - points.cy) / points.fy * camera.fy + camera.cy - v));
  if (apart <= kMostApartPx)
    return;
  char px[32];
  std::snprintf(px, sizeof px, "%.1f", apart);
  throw InvalidInputError(what + " was made by a camera of " + points.intrinsicsText() + ", not by " + source + " (" +
                          camera.intrinsicsText() + "; a ray lands " + px +
                          " px apart): a cloud of another rig? Give the rig it was made with");
}

#define MSF_INSTANTIATE_PINHOLE_CAMERA(T)                                            \
  template PinholeFit fitPinhole<T>(const pcl::PointCloud<T>&);                        \
  template PinholeCamera estimatePinholeCamera<T>(const pcl::PointCloud<T>&, double);
MSF_INSTANTIATE_PINHOLE_CAMERA(pcl::PointXYZ)
MSF_INSTANTIATE_PINHOLE_CAMERA(pcl::PointXYZI)
MSF_INSTANTIATE_PINHOLE_CAMERA(pcl::PointXYZRGB)
MSF_INSTANTIATE_PINHOLE_CAMERA(pcl::PointXYZRGBA)

} // namespace msf
