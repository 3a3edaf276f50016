// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "frame_list.h"
#include "frame_object.h"

#include <msf/common/exceptions.h>

namespace msf::python {

namespace {

/// Item i of `frames` as the FrameObject it must be; with the GIL held.
const FrameObject& frameAt(const py::object& frames, std::size_t i, py::object& item) {
  item = frames[py::int_(i)];
  if (!py::isinstance<FrameObject>(item))
    throw InvalidInputError("item " + std::to_string(i) + " of the frames is a " +
                            py::str(item.get_type().attr("__name__")).cast<std::string>() +
                            ", not a msfusion.Frame");
  return item.cast<const FrameObject&>();
}

} // namespace

FrameList::FrameList(py::object frames, const Calibration& rig)
    : frames_(std::move(frames)), rig_(rig), size_(py::len(frames_)) {}

bool FrameList::hasColor() const {
  const py::gil_scoped_acquire gil;
  if (!has_color_) {
    py::object first;
    has_color_ = size_ > 0 && !frameAt(frames_, 0, first).frame.color.empty();
  }
  return *has_color_;
}

std::string FrameList::frameName(std::size_t i) const {
  const std::lock_guard<std::mutex> lock(names_mutex_);
  const auto name = names_.find(i);
  return name == names_.end() ? std::to_string(i) : name->second;
}

Frame FrameList::load(std::size_t i, bool with_color) const {
  const py::gil_scoped_acquire gil;
  py::object item;
  const FrameObject& object = frameAt(frames_, i, item);
  Frame frame = object.frame;
  if (!object.numbered)
    frame.index = i;
  if (!object.arrays.is_none()) { // it views the caller's arrays, which may go with the item
    frame.left = frame.left.clone();
    frame.right = frame.right.clone();
  }
  if (!with_color)
    frame.color.release();
  const std::lock_guard<std::mutex> lock(names_mutex_);
  names_[frame.index] = object.numbered ? object.name : std::to_string(i);
  return frame;
}

double FrameList::timestamp(std::size_t i) const {
  const py::gil_scoped_acquire gil;
  py::object item;
  return frameAt(frames_, i, item).frame.timestamp;
}

std::string FrameList::description() const { return "a sequence of " + std::to_string(size_) + " frames"; }

} // namespace msf::python
