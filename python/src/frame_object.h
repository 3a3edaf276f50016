// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include "arrays.h"

#include <msf/io/frame_source.h>

#include <string>

namespace msf::python {

/// A frame as Python holds it: the library's Frame (images as the library keeps them: grey,
/// and the colour camera in BGR), its file stem, and the arrays a frame made from arrays views
/// (so its images stay valid as long as it lives; None for a frame a Sequence loaded).
struct FrameObject {
  Frame frame;
  std::string name;
  py::object arrays;
  /// False for a frame made of arrays without an index: an engine's add_frame numbers it by its
  /// place among the frames it was given, so that its messages and result name it.
  bool numbered = true;
};

/// A Python index of a frame of `source` (negative: from the end) as the source's; IndexError
/// outside it.
std::size_t frameIndex(const FrameSource& source, long long i);

} // namespace msf::python
