#include <msf/reconstruction/impl/depth_frame.hpp>

#include <msf/common/exceptions.h>

#include <pcl/point_types.h>

#include <algorithm>
#include <cstring>

namespace msf {

PinholeCamera PinholeCamera::fromCalibration(const Calibration& calibration, int camera) {
  const cv::Size size = calibration.requireImageSize();
  PinholeCamera c;
  c.fx = calibration.fx(camera);
  c.fy = calibration.fy(camera);
  c.cx = calibration.cx(camera);
  c.cy = calibration.cy(camera);
  c.width = size.width;
  c.height = size.height;
  return c;
}

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
}

namespace detail {

void requireOrganized(std::uint32_t width, std::uint32_t height, const std::string& what) {
  if (height <= 1 || width == 0)
    throw InvalidInputError(what + " is not organized (" + std::to_string(width) + "x" + std::to_string(height) +
                            "): integrating it as a depth image needs an organized cloud (width x height of the "
                            "camera image); integrate an unorganized scan with integrateScan and its sensor origin");
}

PinholeCamera PinholeFit::solve(int width, int height, const std::string& what) const {
  const double du = n * saa - sa * sa, dv = n * sbb - sb * sb;
  if (n < 10 || du <= 1e-12 * n * n || dv <= 1e-12 * n * n)
    throw InvalidInputError("cannot recover the camera intrinsics of " + what + ": too few valid points (" +
                            std::to_string(static_cast<long long>(n)) + "); give the calibration");
  PinholeCamera c;
  c.fx = (n * sau - sa * su) / du;
  c.cx = (su - c.fx * sa) / n;
  c.fy = (n * sbv - sb * sv) / dv;
  c.cy = (sv - c.fy * sb) / n;
  c.width = width;
  c.height = height;
  const double ru = suu - 2 * c.fx * sau - 2 * c.cx * su + c.fx * c.fx * saa + 2 * c.fx * c.cx * sa + n * c.cx * c.cx;
  const double rv = svv - 2 * c.fy * sbv - 2 * c.cy * sv + c.fy * c.fy * sbb + 2 * c.fy * c.cy * sb + n * c.cy * c.cy;
  const double rms = std::sqrt(std::max(0.0, ru + rv) / (2 * n));
  if (!(c.fx > 0) || !(c.fy > 0) || !(rms < 0.05))
    throw InvalidInputError("cannot recover the camera intrinsics of " + what +
                            ": its points are not a pinhole projection of its pixels (residual " + std::to_string(rms) +
                            " px); give the calibration");
  return c;
}

} // namespace detail

namespace {
const pcl::PCLPointField* findField(const pcl::PCLPointCloud2& cloud, const char* name) {
  for (const auto& f : cloud.fields)
    if (f.name == name)
      return &f;
  return nullptr;
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
  const pcl::PCLPointField* fw = findField(cloud, "weight");
  if (fw && (fw->datatype != pcl::PCLPointField::FLOAT32 || fw->count != 1))
    throw InvalidInputError(what + ": field 'weight' must be one float32");

  const int rows = static_cast<int>(cloud.height), cols = static_cast<int>(cloud.width);
  if (cloud.data.size() < static_cast<std::size_t>(rows) * cols * cloud.point_step)
    throw InvalidInputError(what + " has fewer data bytes than width x height points");
  DepthFrame frame;
  frame.depth.create(rows, cols, CV_32FC1);
  if (frgb)
    frame.color.create(rows, cols, CV_8UC3);
  if (fw)
    frame.weight.create(rows, cols, CV_32FC1);
  detail::PinholeFit fit;
  for (int v = 0; v < rows; ++v) {
    float* depth = frame.depth.ptr<float>(v);
    for (int u = 0; u < cols; ++u) {
      const std::uint8_t* p = cloud.data.data() + (static_cast<std::size_t>(v) * cols + u) * cloud.point_step;
      const float x = readFloat(p + fx->offset), y = readFloat(p + fy->offset), z = readFloat(p + fz->offset);
      const bool valid = std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && z > 0.f;
      depth[u] = valid ? z : 0.f;
      if (valid && !camera)
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
    }
  }
  frame.camera = camera ? *camera : fit.solve(cols, rows, what);
  frame.validate();
  return frame;
}

#define MSF_INSTANTIATE_DEPTH_FRAME(T)                                                        \
  template PinholeCamera estimatePinholeCamera<T>(const pcl::PointCloud<T>&);                 \
  template DepthFrame toDepthFrame<T>(const pcl::PointCloud<T>&, const PinholeCamera*);
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZ)
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZI)
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZRGB)
MSF_INSTANTIATE_DEPTH_FRAME(pcl::PointXYZRGBA)

} // namespace msf
