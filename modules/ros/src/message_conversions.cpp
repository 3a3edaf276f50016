// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/image_io.h>
#include <msf/ros/message_conversions.h>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

namespace msf {

namespace {

const sensor_msgs::PointField* findField(const sensor_msgs::PointCloud2& message, const std::string& name) {
  for (const auto& field : message.fields)
    if (field.name == name)
      return &field;
  return nullptr;
}

/// Point i's value of a numeric field, whatever its type, as double.
double fieldValue(const sensor_msgs::PointCloud2& message, const sensor_msgs::PointField& field, std::size_t i) {
  const std::uint8_t* p = &message.data[i * message.point_step + field.offset];
  auto read = [p](auto value) {
    std::memcpy(&value, p, sizeof value);
    return static_cast<double>(value);
  };
  switch (field.datatype) {
  case sensor_msgs::PointField::INT8: return read(std::int8_t{});
  case sensor_msgs::PointField::UINT8: return read(std::uint8_t{});
  case sensor_msgs::PointField::INT16: return read(std::int16_t{});
  case sensor_msgs::PointField::UINT16: return read(std::uint16_t{});
  case sensor_msgs::PointField::INT32: return read(std::int32_t{});
  case sensor_msgs::PointField::UINT32: return read(std::uint32_t{});
  case sensor_msgs::PointField::FLOAT32: return read(float{});
  default: return read(double{});
  }
}

/// Writes `value` into point i's field. A packed layout (x, y, z, intensity, a uint16 ring, then
/// a float time: 22 bytes a point) leaves fields unaligned, so neither side goes through a typed
/// reference.
template <typename T>
void putField(sensor_msgs::PointCloud2& message, const sensor_msgs::PointField& field, std::size_t i, T value) {
  std::memcpy(&message.data[i * message.point_step + field.offset], &value, sizeof value);
}

/// x, y and z of one number each (float32, float64 or an integer), and the fields read (those and
/// intensity, ring, time) within a point.
void requireLayout(const sensor_msgs::PointCloud2& message, const std::string& what) {
  for (const char* name : {"x", "y", "z"})
    if (!findField(message, name)) {
      std::string names;
      for (const auto& f : message.fields)
        names += (names.empty() ? "" : " ") + f.name;
      throw InvalidInputError(what + ": PointCloud2 has no field '" + name + "' (fields: " +
                              (names.empty() ? std::string("none") : names) + ")");
    }
  const std::size_t points = static_cast<std::size_t>(message.width) * message.height;
  if (message.point_step == 0 || message.data.size() < points * message.point_step)
    throw InvalidInputError(what + ": PointCloud2 holds " + std::to_string(message.data.size()) + " bytes, not the " +
                            std::to_string(points) + " points of " + std::to_string(message.point_step) +
                            " bytes its header says");
  for (const auto& field : message.fields) {
    if (!(field.name == "x" || field.name == "y" || field.name == "z" || field.name == "intensity" ||
          field.name == "i" || field.name == "ring" || field.name == "time"))
      continue;
    std::size_t bytes = 0;
    try { // PointField's own sizes (sensor_msgs/impl/point_cloud2_iterator.h)
      bytes = static_cast<std::size_t>(::sizeOfPointField(field.datatype));
    } catch (const std::runtime_error&) {
      throw InvalidInputError(what + ": PointCloud2 field '" + field.name + "' has datatype " +
                              std::to_string(field.datatype) + ", which sensor_msgs/PointField does not define");
    }
    if (field.offset + bytes * std::max<std::uint32_t>(field.count, 1) > message.point_step)
      throw InvalidInputError(what + ": PointCloud2 field '" + field.name + "' lies beyond its point step");
  }
  for (const char* name : {"x", "y", "z"})
    if (findField(message, name)->count != 1)
      throw InvalidInputError(what + ": PointCloud2 field '" + std::string(name) + "' holds " +
                              std::to_string(findField(message, name)->count) + " numbers, not one");
}

/// cv_bridge's conversion to `encoding`, its exception as ours.
cv::Mat convertImage(const sensor_msgs::Image& message, const std::string& encoding, const std::string& what) {
  try {
    return cv_bridge::toCvCopy(message, encoding)->image;
  } catch (const std::exception& e) {
    throw InvalidInputError(what + ": image of encoding '" + message.encoding + "' cannot be read as " + encoding +
                            ": " + e.what());
  }
}

/// The Image as grey or BGR at its own bits a channel: 16-bit ones kept 16-bit.
cv::Mat convertKeepingBits(const sensor_msgs::Image& message, bool grey, const std::string& what) {
  namespace enc = sensor_msgs::image_encodings;
  bool sixteen = false;
  try {
    sixteen = enc::bitDepth(message.encoding) == 16;
  } catch (const std::exception&) { // an encoding it does not know: convertImage names it
  }
  return convertImage(message, grey ? (sixteen ? enc::MONO16 : enc::MONO8) : (sixteen ? enc::BGR16 : enc::BGR8),
                      what);
}

} // namespace

std::int64_t stampNs(const ros::Time& stamp) { return static_cast<std::int64_t>(stamp.toNSec()); }

ros::Time stampFromNs(std::int64_t ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(ns));
  return t;
}

void scanFromMessage(const sensor_msgs::PointCloud2& message, Frame& frame, const std::string& what) {
  requireLayout(message, what);
  const sensor_msgs::PointField* intensity = findField(message, "intensity");
  if (!intensity)
    intensity = findField(message, "i");
  const sensor_msgs::PointField* ring = findField(message, "ring");
  const sensor_msgs::PointField* time = findField(message, "time");
  const std::size_t points = static_cast<std::size_t>(message.width) * message.height;

  frame.scan.reset(new pcl::PointCloud<pcl::PointXYZI>);
  frame.scan->reserve(points);
  frame.point_ring.clear();
  frame.point_time_s.clear();
  const sensor_msgs::PointField &x = *findField(message, "x"), &y = *findField(message, "y"),
                                 &z = *findField(message, "z");
  for (std::size_t i = 0; i < points; ++i) {
    pcl::PointXYZI p;
    p.x = static_cast<float>(fieldValue(message, x, i));
    p.y = static_cast<float>(fieldValue(message, y, i));
    p.z = static_cast<float>(fieldValue(message, z, i));
    p.intensity = intensity ? static_cast<float>(fieldValue(message, *intensity, i)) : 0.f;
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.intensity))
      continue;
    frame.scan->push_back(p);
    if (ring)
      frame.point_ring.push_back(static_cast<std::uint16_t>(fieldValue(message, *ring, i)));
    if (time)
      frame.point_time_s.push_back(static_cast<float>(fieldValue(message, *time, i)));
  }
  if (!frame.point_time_s.empty()) {
    const float start = *std::min_element(frame.point_time_s.begin(), frame.point_time_s.end());
    for (float& t : frame.point_time_s)
      t -= start;
  }
  frame.scan->width = static_cast<std::uint32_t>(frame.scan->size());
  frame.scan->height = 1;
  frame.scan->is_dense = true;
}

bool scanTimesAreOneInstant(const Frame& frame) {
  // scanFromMessage counts the times from the earliest: one instant is all zeros.
  return !frame.point_time_s.empty() &&
         std::all_of(frame.point_time_s.begin(), frame.point_time_s.end(), [](float t) { return t == 0.f; });
}

sensor_msgs::PointCloud2 scanToMessage(const Frame& frame, const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 message;
  message.header = header;
  sensor_msgs::PointCloud2Modifier modifier(message);
  const bool with_ring = frame.point_ring.size() == frame.scan->size();
  const bool with_time = frame.point_time_s.size() == frame.scan->size();
  using F = sensor_msgs::PointField;
  if (with_ring && with_time)
    modifier.setPointCloud2Fields(6, "x", 1, F::FLOAT32, "y", 1, F::FLOAT32, "z", 1, F::FLOAT32, "intensity", 1,
                                  F::FLOAT32, "ring", 1, F::UINT16, "time", 1, F::FLOAT32);
  else if (with_ring)
    modifier.setPointCloud2Fields(5, "x", 1, F::FLOAT32, "y", 1, F::FLOAT32, "z", 1, F::FLOAT32, "intensity", 1,
                                  F::FLOAT32, "ring", 1, F::UINT16);
  else if (with_time)
    modifier.setPointCloud2Fields(5, "x", 1, F::FLOAT32, "y", 1, F::FLOAT32, "z", 1, F::FLOAT32, "intensity", 1,
                                  F::FLOAT32, "time", 1, F::FLOAT32);
  else
    modifier.setPointCloud2Fields(4, "x", 1, F::FLOAT32, "y", 1, F::FLOAT32, "z", 1, F::FLOAT32, "intensity", 1,
                                  F::FLOAT32);
  modifier.resize(frame.scan->size());
  message.is_dense = true;
  const sensor_msgs::PointField &x = *findField(message, "x"), &y = *findField(message, "y"),
                                 &z = *findField(message, "z"), &intensity = *findField(message, "intensity");
  const sensor_msgs::PointField* ring = findField(message, "ring");
  const sensor_msgs::PointField* time = findField(message, "time");
  for (std::size_t k = 0; k < frame.scan->size(); ++k) {
    const auto& p = (*frame.scan)[k];
    putField(message, x, k, p.x);
    putField(message, y, k, p.y);
    putField(message, z, k, p.z);
    putField(message, intensity, k, p.intensity);
    if (ring)
      putField(message, *ring, k, frame.point_ring[k]);
    if (time)
      putField(message, *time, k, frame.point_time_s[k]);
  }
  return message;
}

void greyPairFromMessages(const sensor_msgs::Image& left, const sensor_msgs::Image& right, cv::Mat& left_grey,
                          cv::Mat& right_grey, const std::string& what_left, const std::string& what_right) {
  const cv::Mat l = convertKeepingBits(left, true, what_left), r = convertKeepingBits(right, true, what_right);
  const int bits = pairBits(l, r);
  left_grey = toEightBit(l, bits);
  right_grey = toEightBit(r, bits);
}

cv::Mat colorFromMessage(const sensor_msgs::Image& message, const std::string& what) {
  const cv::Mat image = convertKeepingBits(message, false, what);
  return toEightBit(image, significantBits(image));
}

sensor_msgs::Image imageToMessage(const cv::Mat& image, const std_msgs::Header& header) {
  const std::string encoding = image.type() == CV_8UC1   ? sensor_msgs::image_encodings::MONO8
                               : image.type() == CV_8UC3 ? sensor_msgs::image_encodings::BGR8
                               : image.type() == CV_32FC1
                                   ? sensor_msgs::image_encodings::TYPE_32FC1
                                   : throw InvalidInputError("an image of OpenCV type " + std::to_string(image.type()) +
                                                             " has no ROS encoding here (8UC1, 8UC3, 32FC1)");
  sensor_msgs::Image message;
  cv_bridge::CvImage(header, encoding, image).toImageMsg(message);
  return message;
}

Calibration::Projection projectionFromCameraInfo(const sensor_msgs::CameraInfo& info, const std::string& what) {
  Calibration::Projection P;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      P(r, c) = info.P[static_cast<std::size_t>(4 * r + c)];
  if (P.isZero())
    throw InvalidInputError(what + ": CameraInfo's P is all zero (the camera is not calibrated)");
  return P;
}

sensor_msgs::CameraInfo cameraInfoFromCalibration(const Calibration& calibration, int camera,
                                                  const std_msgs::Header& header) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = static_cast<std::uint32_t>(calibration.image_size.width);
  info.height = static_cast<std::uint32_t>(calibration.image_size.height);
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  const Calibration::Projection& P = calibration.P.at(static_cast<std::size_t>(camera));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c)
      info.P[static_cast<std::size_t>(4 * r + c)] = P(r, c);
    for (int c = 0; c < 3; ++c) {
      info.K[static_cast<std::size_t>(3 * r + c)] = P(r, c);
      info.R[static_cast<std::size_t>(3 * r + c)] = r == c ? 1.0 : 0.0;
    }
  }
  return info;
}

Calibration rigFromCameraInfo(const sensor_msgs::CameraInfo& left, const sensor_msgs::CameraInfo& right,
                              const sensor_msgs::CameraInfo* color, const Eigen::Isometry3d& T_cam0_velo,
                              cv::Size image_size, const std::string& source) {
  Calibration c;
  c.source = source;
  c.image_size = image_size;
  c.P[0] = projectionFromCameraInfo(left, source + ", the left camera");
  c.P[1] = projectionFromCameraInfo(right, source + ", the right camera");
  c.P[2] = color ? projectionFromCameraInfo(*color, source + ", the colour camera") : c.P[0];
  c.P[3] = c.P[2];
  c.P[3].col(3) += (c.P[1].col(3) - c.P[0].col(3)) * (c.fx(2) / c.fx(0));
  c.T_cam0_velo = T_cam0_velo;
  c.validate();
  return c;
}

void stampFrame(Frame& frame, std::size_t index, std::int64_t scan_ns, std::int64_t first_scan_ns,
                const std::string& lidar_frame) {
  frame.index = index;
  frame.timestamp = static_cast<double>(scan_ns - first_scan_ns) / 1e9;
  frame.scan->header.frame_id = lidar_frame;
  frame.scan->header.stamp = static_cast<std::uint64_t>(std::llround(std::max(0.0, frame.timestamp) * 1e6));
  frame.scan->header.seq = static_cast<std::uint32_t>(index);
}

Eigen::Isometry3d isometryFromTransform(const geometry_msgs::Transform& transform) {
  const auto& q = transform.rotation;
  const auto& t = transform.translation;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(t.x, t.y, t.z);
  return T;
}

geometry_msgs::Transform transformFromIsometry(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  geometry_msgs::Transform transform;
  transform.rotation.x = q.x();
  transform.rotation.y = q.y();
  transform.rotation.z = q.z();
  transform.rotation.w = q.w();
  transform.translation.x = T.translation().x();
  transform.translation.y = T.translation().y();
  transform.translation.z = T.translation().z();
  return transform;
}

visualization_msgs::Marker meshToMarker(const TriangleMesh& mesh, const std_msgs::Header& header) {
  visualization_msgs::Marker marker;
  marker.header = header;
  marker.ns = "msf_mesh";
  marker.type = visualization_msgs::Marker::TRIANGLE_LIST;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
  marker.color.a = 1.0f;
  marker.points.resize(3 * mesh.triangles.size());
  const bool colored = mesh.colors.size() == mesh.vertices.size();
  if (colored)
    marker.colors.resize(marker.points.size());
  std::size_t k = 0;
  for (const auto& triangle : mesh.triangles)
    for (const std::uint32_t v : triangle) {
      const Eigen::Vector3f& p = mesh.vertices[v];
      marker.points[k].x = p.x();
      marker.points[k].y = p.y();
      marker.points[k].z = p.z();
      if (colored) {
        auto& c = marker.colors[k];
        c.r = mesh.colors[v][0] / 255.f;
        c.g = mesh.colors[v][1] / 255.f;
        c.b = mesh.colors[v][2] / 255.f;
        c.a = 1.f;
      }
      ++k;
    }
  return marker;
}

} // namespace msf
