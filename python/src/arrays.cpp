// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "arrays.h"

#include <msf/common/exceptions.h>
#include <msf/common/limits.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace msf::python {

namespace {

py::dtype dtypeOf(int depth) {
  switch (depth) {
  case CV_8U:
    return py::dtype::of<std::uint8_t>();
  case CV_16U:
    return py::dtype::of<std::uint16_t>();
  case CV_32S:
    return py::dtype::of<std::int32_t>();
  case CV_32F:
    return py::dtype::of<float>();
  case CV_64F:
    return py::dtype::of<double>();
  default:
    throw InvalidInputError("an image of OpenCV depth " + std::to_string(depth) + " has no numpy dtype here");
  }
}

std::string text(const py::handle& object) { return py::str(object).cast<std::string>(); }

std::string shapeText(const py::array& array) {
  std::string shape = "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i)
    shape += (i ? ", " : "") + std::to_string(array.shape(i));
  return shape + (array.ndim() == 1 ? ",)" : ")");
}

py::array requireArray(const py::handle& object, const char* name) {
  if (!py::isinstance<py::array>(object))
    throw InvalidInputError(std::string(name) + " must be a numpy array, got " +
                            text(object.get_type().attr("__name__")));
  return py::reinterpret_borrow<py::array>(object);
}

// EquivTypes, not the type number alone: a byte-swapped float32 is not float32 in memory.
bool equivalent(const py::dtype& a, const py::dtype& b) {
  return py::detail::npy_api::get().PyArray_EquivTypes_(a.ptr(), b.ptr());
}

void requireDtype(const py::array& array, const char* name, int depth) {
  const py::dtype wanted = dtypeOf(depth);
  if (equivalent(array.dtype(), wanted))
    return;
  // .astype(uint8) of wider values keeps their low byte, and of a float image in 0..1 zeros and ones.
  const std::string how = depth == CV_8U ? "scale it to 0..255 first, then .astype(numpy.uint8)"
                                         : "convert it with .astype(numpy." + text(wanted) + ")";
  throw InvalidInputError(std::string(name) + " must be " + text(wanted) + ", got " + text(array.dtype()) + " (" +
                          how + ")");
}

void requireContiguous(const py::array& array, const char* name) {
  if (!(array.flags() & py::array::c_style))
    throw InvalidInputError(std::string(name) + " must be C-contiguous (a slice, a transpose or a channel of an "
                            "image is not): pass numpy.ascontiguousarray(" + name + ")");
}

/// An array over `mat`'s buffer that keeps `base` alive; `mat` must be continuous.
py::array arrayOver(const cv::Mat& mat, const py::handle& base) {
  std::vector<py::ssize_t> shape{mat.rows, mat.cols};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(mat.step[0]), static_cast<py::ssize_t>(mat.elemSize())};
  if (mat.channels() > 1) {
    shape.push_back(mat.channels());
    strides.push_back(static_cast<py::ssize_t>(mat.elemSize1()));
  }
  return py::array(dtypeOf(mat.depth()), shape, strides, mat.data, base);
}

} // namespace

cv::Mat imageView(const py::handle& object, const char* name, int type, cv::Size expected) {
  const py::array array = requireArray(object, name);
  const int channels = CV_MAT_CN(type);
  const bool shape_ok = channels == 1 ? array.ndim() == 2 : array.ndim() == 3 && array.shape(2) == channels;
  if (!shape_ok)
    throw InvalidInputError(std::string(name) + " must have shape " +
                            (channels == 1 ? std::string("(H, W)") : "(H, W, " + std::to_string(channels) + ")") +
                            ", got " + shapeText(array));
  requireDtype(array, name, CV_MAT_DEPTH(type));
  requireContiguous(array, name);
  const py::ssize_t rows = array.shape(0), cols = array.shape(1);
  limits::checkImageSize(cols, rows, name);
  if (expected != cv::Size() && (cols != expected.width || rows != expected.height))
    throw InvalidInputError(std::string(name) + " is " + std::to_string(cols) + "x" + std::to_string(rows) +
                            " (W x H), expected " + std::to_string(expected.width) + "x" +
                            std::to_string(expected.height));
  return cv::Mat(static_cast<int>(rows), static_cast<int>(cols), type, const_cast<void*>(array.data()));
}

bool hasDepth(const py::handle& object, int depth) {
  return py::isinstance<py::array>(object) &&
         equivalent(py::reinterpret_borrow<py::array>(object).dtype(), dtypeOf(depth));
}

cv::Mat optionalImageView(const py::handle& object, const char* name, int type, cv::Size expected) {
  return object.is_none() ? cv::Mat() : imageView(object, name, type, expected);
}

void requireValuesIn(const cv::Mat& image, const char* name, float lo, float hi, bool nan_allowed,
                     const std::string& hint) {
  for (int v = 0; v < image.rows; ++v) {
    const float* row = image.ptr<float>(v);
    for (int u = 0; u < image.cols; ++u) {
      const float x = row[u];
      if (std::isnan(x) ? nan_allowed : x >= lo && x <= hi)
        continue;
      std::ostringstream value;
      value << x;
      throw InvalidInputError(std::string(name) + " holds " + value.str() + " at row " + std::to_string(v) +
                              ", column " + std::to_string(u) + ": " + hint);
    }
  }
}

void requireDepthValues(const cv::Mat& image, const char* name) {
  constexpr float kMax = std::numeric_limits<float>::max();
  requireValuesIn(image, name, -kMax, kMax, true, "give 0 or NaN where there is no depth");
}

void requireWeightValues(const cv::Mat& image, const char* name) {
  requireValuesIn(image, name, 0.f, std::numeric_limits<float>::max(), false,
                  "a weight is an inverse variance (m^-2), finite and not negative");
}

cv::Mat rowsView(const py::handle& object, const char* name, int depth, int min_columns, int max_columns) {
  const py::array array = requireArray(object, name);
  const std::string wanted = min_columns == max_columns
                                 ? "(N, " + std::to_string(min_columns) + ")"
                                 : "(N, " + std::to_string(min_columns) + ") or (N, " + std::to_string(max_columns) + ")";
  if (array.ndim() != 2 || array.shape(1) < min_columns || array.shape(1) > max_columns)
    throw InvalidInputError(std::string(name) + " must have shape " + wanted + ", got " + shapeText(array));
  requireDtype(array, name, depth);
  requireContiguous(array, name);
  if (array.shape(0) > std::numeric_limits<int>::max())
    throw InvalidInputError(std::string(name) + " has more than 2^31 rows");
  return cv::Mat(static_cast<int>(array.shape(0)), static_cast<int>(array.shape(1)), CV_MAKETYPE(depth, 1),
                 const_cast<void*>(array.data()));
}

cv::Mat scanView(const py::handle& array) {
  return rowsView(array, "scan", hasDepth(array, CV_64F) ? CV_64F : CV_32F, 3, 4);
}

pcl::PointCloud<pcl::PointXYZI>::Ptr scanFromPoints(const cv::Mat& given) {
  cv::Mat points = given;
  if (points.depth() == CV_64F) // Open3D's and most numpy code's points: to PCL's floats
    given.convertTo(points, CV_32F);
  pcl::PointCloud<pcl::PointXYZI>::Ptr scan(new pcl::PointCloud<pcl::PointXYZI>);
  scan->resize(static_cast<std::size_t>(points.rows));
  const bool has_reflectance = points.cols == 4;
  for (int i = 0; i < points.rows; ++i) {
    const float* p = points.ptr<float>(i);
    pcl::PointXYZI& q = (*scan)[static_cast<std::size_t>(i)];
    q.x = p[0];
    q.y = p[1];
    q.z = p[2];
    q.intensity = has_reflectance ? p[3] : 0.f;
  }
  return scan;
}

py::object toArray(const pcl::PointCloud<pcl::PointXYZI>& scan) {
  if (scan.empty())
    return py::array_t<float>(std::vector<py::ssize_t>{0, 4});
  cv::Mat points(static_cast<int>(scan.size()), 4, CV_32FC1);
  for (int i = 0; i < points.rows; ++i) {
    const pcl::PointXYZI& p = scan[static_cast<std::size_t>(i)];
    float* q = points.ptr<float>(i);
    q[0] = p.x;
    q[1] = p.y;
    q[2] = p.z;
    q[3] = p.intensity;
  }
  return toArray(points);
}

py::object toArray(cv::Mat mat) {
  if (mat.empty())
    return py::none();
  if (!mat.isContinuous())
    mat = mat.clone();
  auto owner = std::make_unique<cv::Mat>(std::move(mat));
  py::capsule base(owner.get(), [](void* p) { delete static_cast<cv::Mat*>(p); });
  return arrayOver(*owner.release(), base);
}

py::object viewOf(const cv::Mat& mat, const py::handle& owner) {
  if (mat.empty())
    return py::none();
  return mat.isContinuous() ? py::object(arrayOver(mat, owner)) : toArray(mat.clone());
}

Eigen::Isometry3d poseFrom(const py::handle& object, const char* name) {
  const py::array array = requireArray(object, name);
  if (array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4)
    throw InvalidInputError(std::string(name) + " must have shape (4, 4), got " + shapeText(array));
  if (array.dtype().kind() != 'f')
    throw InvalidInputError(std::string(name) + " must be a float array (float64 or float32), got " +
                            text(array.dtype()));
  const auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  Eigen::Isometry3d T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      T.matrix()(r, c) = values.at(r, c);
  limits::checkRigid(T, name);
  return T;
}

py::array_t<double> toArray(const Eigen::Isometry3d& pose) {
  py::array_t<double> array(std::vector<py::ssize_t>{4, 4});
  auto out = array.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      out(r, c) = pose.matrix()(r, c);
  return array;
}

} // namespace msf::python
