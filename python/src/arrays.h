// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// numpy arrays in and out of the library's types: inputs are viewed in place (a cv::Mat over
// the array's buffer), outputs own the cv::Mat they came from (a capsule frees it with the
// array), so no image is copied on its way through the binding.
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <mutex>
#include <utility>

namespace msf::python {

namespace py = pybind11;

/// An argument of any Python object that the binding checks itself, with a message naming what
/// is wrong (pybind11's own check would say only "incompatible function arguments"); its type
/// name `Shown::name` is what signatures and help() show.
template <typename Shown>
class Checked : public py::object {
public:
  PYBIND11_OBJECT_DEFAULT(Checked, py::object, anyObject)

private:
  static bool anyObject(PyObject*) { return true; }
};

struct ShownAsArray {
  static constexpr auto name = py::detail::const_name("numpy.ndarray");
};
struct ShownAsCamera {
  static constexpr auto name = py::detail::const_name("PinholeCamera | Calibration");
};
/// A numpy array argument (imageView, rowsView and poseFrom check it); None where optional.
using ArrayArg = Checked<ShownAsArray>;
/// A camera argument: a PinholeCamera, or a Calibration for its camera 0.
using CameraArg = Checked<ShownAsCamera>;

/// A cv::Mat over `array`'s buffer, no copy: (H,W) for one channel, (H,W,C) for `channels`
/// > 1. `type` is CV_8UC1, CV_8UC3, CV_32FC1... Throws InvalidInputError naming `name` when
/// `array` is not a numpy array, has another dtype or shape, or is not C-contiguous. An
/// `expected` size other than 0x0 is checked too. The array must outlive the view.
cv::Mat imageView(const py::handle& array, const char* name, int type, cv::Size expected = {});

/// The same for an optional argument: an empty cv::Mat for None.
cv::Mat optionalImageView(const py::handle& array, const char* name, int type, cv::Size expected = {});

/// Whether `array` is a numpy array of OpenCV depth `depth`'s dtype (CV_16U: uint16).
bool hasDepth(const py::handle& array, int depth);

/// Throws InvalidInputError naming `name` and the first pixel of a CV_32FC1 `image` (empty: none)
/// outside lo..hi, or NaN unless `nan_allowed` (a depth image's NaN is no depth, as its 0);
/// `hint` ends the message.
void requireValuesIn(const cv::Mat& image, const char* name, float lo, float hi, bool nan_allowed,
                     const std::string& hint);
/// A depth image: anything but +-inf (0, a negative depth and NaN are no depth).
void requireDepthValues(const cv::Mat& image, const char* name);
/// A weight image (m^-2): finite and not negative.
void requireWeightValues(const cv::Mat& image, const char* name);

/// A one-channel cv::Mat of N rows over a C-contiguous array of shape (N, C), no copy, with
/// min_columns <= C <= max_columns (points: x y z and maybe reflectance; triangles). `depth`:
/// CV_32F, CV_32S, CV_8U... Throws InvalidInputError naming `name` as imageView.
cv::Mat rowsView(const py::handle& array, const char* name, int depth, int min_columns, int max_columns);

/// rowsView of a scan argument: (N, 3) or (N, 4) x y z [reflectance], float32 or float64.
cv::Mat scanView(const py::handle& array);
/// A LiDAR scan from scanView's rows: a copy, as PCL's points are 32 bytes (reflectance 0 for
/// (N, 3)).
pcl::PointCloud<pcl::PointXYZI>::Ptr scanFromPoints(const cv::Mat& points);
/// A scan as an (N, 4) float32 array of x y z reflectance (a copy).
py::object toArray(const pcl::PointCloud<pcl::PointXYZI>& scan);

/// An array that owns `mat` (its buffer is shared, not copied): (H,W) or (H,W,C); None for
/// an empty `mat`. A region of interest is copied, so that every output is C-contiguous.
py::object toArray(cv::Mat mat);
/// A view of `mat`, kept alive by `owner` (the Python object that holds the cv::Mat); None
/// for an empty `mat`, a copy for a region of interest.
py::object viewOf(const cv::Mat& mat, const py::handle& owner);

/// A 4x4 rigid transform (any float dtype; the translation in metres). Throws
/// InvalidInputError naming `name` for another shape or a transform that is not rigid.
Eigen::Isometry3d poseFrom(const py::handle& array, const char* name);
/// A 4x4 float64 array.
py::array_t<double> toArray(const Eigen::Isometry3d& pose);

/// Runs `work` with the GIL released and `mutex` held: heavy calls let other Python threads
/// run, and calls on one object from several threads take turns (the stages keep buffers).
template <typename Mutex, typename Work>
auto withoutGil(Mutex& mutex, Work&& work) {
  py::gil_scoped_release release;
  std::lock_guard<Mutex> lock(mutex);
  return std::forward<Work>(work)();
}

} // namespace msf::python

namespace pybind11::detail {
template <typename Shown>
struct handle_type_name<msf::python::Checked<Shown>> {
  static constexpr auto name = Shown::name;
};
} // namespace pybind11::detail
