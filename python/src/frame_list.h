// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include "arrays.h"

#include <msf/io/frame_source.h>

#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

namespace msf::python {

/// A program's own frames, a Python sequence of msfusion.Frame (a list, or any object with len()
/// and [i]), as a FrameSource of the engine's rig: what lets run() overlap the stages over frames
/// made of arrays. load() takes the GIL to read item i, numbers a Frame made without an index by
/// its place, and copies the images it views, since the item may go once read; each item is read
/// once a run (a sequence may make its frames when asked). Made and destroyed with the GIL held.
class FrameList : public FrameSource {
public:
  FrameList(py::object frames, const Calibration& rig);

  const Calibration& calibration() const override { return rig_; }
  std::size_t size() const override { return size_; }
  /// The Frame's name, once it was loaded; its index before.
  std::string frameName(std::size_t i) const override;
  Frame load(std::size_t i, bool with_color = true) const override;
  double timestamp(std::size_t i) const override;
  std::string description() const override;
  /// Whether its first Frame has a colour image (reads item 0 when first asked).
  bool hasColor() const override;

private:
  py::object frames_;
  Calibration rig_;
  std::size_t size_ = 0;
  mutable std::optional<bool> has_color_; // read and written with the GIL held
  mutable std::mutex names_mutex_;
  mutable std::unordered_map<std::size_t, std::string> names_;  // by Frame::index, as the engine asks
};

} // namespace msf::python
