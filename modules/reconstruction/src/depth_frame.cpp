// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/reconstruction/impl/depth_frame.hpp>
#include <msf/io/point_types.h>

#include <msf/common/exceptions.h>

#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace msf {

void DepthFrame::validate() const {
  if (depth.empty() || depth.type() != CV_32FC1)
    throw InvalidInputError("depth frame: the depth image must be a non-empty CV_32FC1 image (metres)");
  if (!camera.valid())
    throw InvalidInputError("depth frame: the camera intrinsics are invalid (fx, fy, width and height must be > 0)");
  if (camera.width != depth.cols || camera.height != depth.rows)
    throw InvalidInputError("depth frame: the depth image is " + std::to_string(depth.cols) + "x" +
                            std::to_string(depth.rows) + " but the camera is " + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height));
  if (!color.empty() && (color.type() != CV_8UC3 || color.size() != depth.size()))
    throw InvalidInputError("depth frame: the colour image must be CV_8UC3 of the depth image's size");
  if (!weight.empty() && (weight.type() != CV_32FC1 || weight.size() != depth.size()))
    throw InvalidInputError("depth frame: the weight image must be CV_32FC1 of the depth image's size");
  if (!free_space_weight.empty() && (free_space_weight.type() != CV_32FC1 || free_space_weight.size() != depth.size()))
    throw InvalidInputError("depth frame: the free-space weight image must be CV_32FC1 of the depth image's size");
}

namespace detail {

void requireOrganized(std::uint32_t width, std::uint32_t height, const std::string& what) {
  if (height <= 1 || width == 0)
    throw InvalidInputError(what + " is not organized (" + std::to_string(width) + "x" + std::to_string(height) +
                            "): integrating it as a depth image needs an organized cloud (width x height of the "
                            "camera image); integrate an unorganized scan with integrateScan and its sensor origin");
}

} // namespace detail

namespace {
const pcl::PCLPointField* findField(const pcl::PCLPointCloud2& cloud, const char* name) {
  for (const auto& f : cloud.fields)
    if (f.name == name)
      return &f;
  return nullptr;
}

/// A field of one float32 that the cloud may have (nullptr when it has none).
const pcl::PCLPointField* optionalFloatField(const pcl::PCLPointCloud2& cloud, const char* name,
                                             const std::string& what) {
  const pcl::PCLPointField* field = findField(cloud, name);
  if (field && (field->datatype != pcl::PCLPointField::FLOAT32 || field->count != 1))
    throw InvalidInputError(what + ": field '" + name + "' must be one float32");
  return field;
}

float readFloat(const std::uint8_t* p) {
  float f;
  std::memcpy(&f, p, sizeof f);
  return f;
}
} // namespace

DepthFrame toDepthFrame(const pcl::PCLPointCloud2& cloud, const PinholeCamera* camera, const std::string& what) {
  detail::requireOrganized(cloud.width, cloud.height, what);
  const pcl::PCLPointField* fx = findField(cloud, "x");
  const pcl::PCLPointField* fy = findField(cloud, "y");
  const pcl::PCLPointField* fz = findField(cloud, "z");
  for (const auto* f : {fx, fy, fz})
    if (!f || f->datatype != pcl::PCLPointField::FLOAT32 || f->count != 1)
      throw InvalidInputError(what + " has no float32 field x, y and z");
  const pcl::PCLPointField* frgb = findField(cloud, "rgb");
  if (!frgb)
    frgb = findField(cloud, "rgba");
  const pcl::PCLPointField* fw = optionalFloatField(cloud, "weight", what);
  const pcl::PCLPointField* ffree = optionalFloatField(cloud, "free_space_weight", what);

  const int rows = static_cast<int>(cloud.height), cols = static_cast<int>(cloud.width);
  if (cloud.data.size() < static_cast<std::size_t>(rows) * cols * cloud.point_step)
    throw InvalidInputError(what + " has fewer data bytes than width x height points");
  DepthFrame frame;
  frame.depth.create(rows, cols, CV_32FC1);
  if (frgb)
    frame.color.create(rows, cols, CV_8UC3);
  if (fw)
    frame.weight.create(rows, cols, CV_32FC1);
  if (ffree)
    frame.free_space_weight.create(rows, cols, CV_32FC1);
  PinholeFit fit;
  for (int v = 0; v < rows; ++v) {
    float* depth = frame.depth.ptr<float>(v);
    for (int u = 0; u < cols; ++u) {
      const std::uint8_t* p = cloud.data.data() + (static_cast<std::size_t>(v) * cols + u) * cloud.point_step;
      const float x = readFloat(p + fx->offset), y = readFloat(p + fy->offset), z = readFloat(p + fz->offset);
      const bool valid = std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && z > 0.f;
      depth[u] = valid ? z : 0.f;
      if (valid)
        fit.add(u, v, x, y, z);
      if (frgb) {
        std::uint32_t rgb;
        std::memcpy(&rgb, p + frgb->offset, sizeof rgb);
        std::uint8_t* bgr = frame.color.ptr<std::uint8_t>(v) + 3 * u;
        bgr[0] = static_cast<std::uint8_t>(rgb & 0xff);
        bgr[1] = static_cast<std::uint8_t>((rgb >> 8) & 0xff);
        bgr[2] = static_cast<std::uint8_t>((rgb >> 16) & 0xff);
      }
      if (fw) {
        const float w = readFloat(p + fw->offset);
        frame.weight.ptr<float>(v)[u] = std::isfinite(w) && w > 0.f ? w : 0.f;
      }
      if (ffree) {
        const float w = readFloat(p + ffree->offset);
        frame.free_space_weight.ptr<float>(v)[u] = std::isfinite(w) && w > 0.f ? w : 0.f;
      }
    }
  }
  if (camera)
    requireCameraOfPoints(fit, *camera, what, "the camera given");
  frame.camera = camera ? *camera : fit.solve(cols, rows, what);
  frame.validate();
  return frame;
}

cv::Mat readSkyDepth(const pcl::PCLPointCloud2& cloud, const std::string& what) {
  const pcl::PCLPointField* field = optionalFloatField(cloud, "sky_depth", what);
  if (!field)
    return cv::Mat();
  detail::requireOrganized(cloud.width, cloud.height, what);
  const int rows = static_cast<int>(cloud.height), cols = static_cast<int>(cloud.width);
  if (cloud.data.size() < static_cast<std::size_t>(rows) * cols * cloud.point_step)
    throw InvalidInputError(what + " has fewer data bytes than width x height points");
  cv::Mat sky_depth(rows, cols, CV_32FC1);
  for (int v = 0; v < rows; ++v)
    for (int u = 0; u < cols; ++u)
      sky_depth.ptr<float>(v)[u] =
          readFloat(cloud.data.data() + (static_cast<std::size_t>(v) * cols + u) * cloud.point_step + field->offset);
  checkSkyDepthBounds(sky_depth, what + ": field 'sky_depth'");
  return sky_depth;
}

void checkSkyDepthBounds(const cv::Mat& sky_depth, const std::string& what) {
  for (int v = 0; v < sky_depth.rows; ++v) {
    const float* depth = sky_depth.ptr<float>(v);
    for (int u = 0; u < sky_depth.cols; ++u)
      if (!std::isnan(depth[u]) && !(depth[u] > 0.f))
        throw InvalidInputError(what + " at pixel (" + std::to_string(u) + ", " + std::to_string(v) + ") is " +
                                std::to_string(depth[u]) + ": a pixel's bound is NaN (not sky), a depth > 0 or +inf "
                                "(the whole ray)");
  }
}

#define MSF_INSTANTIATE_DEPTH_FRAME(T)                                                        \
  template DepthFrame toDepthFrame<T>(const pcl::PointCloud<T>&, const PinholeCamera*);
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZ)
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZI)
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZRGB)
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZRGBA)
MSF_INSTANTIATE_DEPTH_FRAME(msf::PointXYZID)            // msf_interpolate's
MSF_INSTANTIATE_DEPTH_FRAME(msf::PointXYZRGBConfidence) // msf_stereo's
MSF_INSTANTIATE_DEPTH_FRAME(msf::PointXYZRGBWeight)     // msf_fuse's, its weight per pixel

} // namespace msf
