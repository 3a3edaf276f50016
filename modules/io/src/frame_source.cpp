// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/common/message_text.h>
#include <msf/io/frame_source.h>

#include <cmath>
#include <string>

namespace msf {

FrameRange FrameRange::parse(const std::string& text) {
  FrameRange r;
  auto toInt = [&](const std::string& s, int fallback) {
    if (s.empty())
      return fallback;
    std::size_t used = 0;
    int v = -1;
    try {
      v = std::stoi(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || v < 0)
      throw InvalidInputError("frame range " + quoted(text) + " is not 'a:b' with whole numbers a <= b");
    return v;
  };
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    r.first = r.last = toInt(text, -1);
    if (r.first < 0)
      throw InvalidInputError("frame range is empty");
  } else {
    r.first = toInt(text.substr(0, colon), 0);
    r.last = toInt(text.substr(colon + 1), -1);
  }
  if (r.last >= 0 && r.last < r.first)
    throw InvalidInputError("frame range " + quoted(text) + " ends before it starts");
  return r;
}

namespace {


/// An image of `channels` 8-bit channels (1: grey, 3: BGR) and the calibration's size.
void checkImage(const cv::Mat& image, const std::string& what, const Calibration& calibration, int channels,
                bool optional) {
  if (image.empty()) {
    if (optional)
      return;
    throw InvalidInputError(what + " is missing or empty");
  }
  if (image.type() != CV_MAKETYPE(CV_8U, channels))
    throw InvalidInputError(what + " must be " + (channels == 1 ? "8-bit grey (CV_8UC1)" : "8-bit BGR (CV_8UC3)") +
                            ", not " + cv::typeToString(image.type()) +
                            (channels == 1 && image.depth() == CV_8U ? ": convert it with cv::cvtColor" : ""));
  const cv::Size expected = calibration.image_size;
  if (expected.area() > 0 && image.size() != expected)
    throw InvalidInputError(what + " is " + sizeText(image) + " but calibration '" + calibration.source + "' is " +
                            sizeText(expected));
}

} // namespace

void checkFrame(const Frame& frame, const Calibration& calibration) {
  const std::string name = "frame " + std::to_string(frame.index);
  if (!frame.scan || frame.scan->empty())
    throw InvalidInputError(name + " has no scan" + (frame.scan ? " point" : "") +
                            ": the engine needs the LiDAR's points each frame");
  const std::size_t points = frame.scan->size();
  for (const auto& [count, what] : {std::pair<std::size_t, const char*>{frame.point_ring.size(), "rings"},
                                    {frame.point_time_s.size(), "times"}})
    if (count != 0 && count != points)
      throw InvalidInputError(name + " has " + std::to_string(count) + " point " + what + " for " +
                              std::to_string(points) + " scan points");
  checkImage(frame.left, name + "'s left image", calibration, 1, false);
  checkImage(frame.right, name + "'s right image", calibration, 1, false);
  checkImage(frame.color, name + "'s colour image", calibration, 3, true);
  if (!std::isfinite(frame.timestamp))
    throw InvalidInputError(name + "'s timestamp is " + std::to_string(frame.timestamp) +
                            ": seconds from the first frame, or 0 when not known");
  if (frame.has_pose)
    limits::checkRigid(frame.T_world_cam0, name + "'s pose T_world_cam0");
}

const Frame& withWholeImages(const Frame& frame, Frame& copy) {
  if (!frame.left.isSubmatrix() && !frame.right.isSubmatrix() && !frame.color.isSubmatrix())
    return frame;
  copy = frame;
  for (cv::Mat* image : {&copy.left, &copy.right, &copy.color})
    if (image->isSubmatrix())
      *image = image->clone();
  return copy;
}

const PoseList& FrameSource::poses() const {
  static const PoseList none;
  return none;
}

long long frameNumber(const std::string& name) {
  if (name.empty() || name.size() > 18 || name.find_first_not_of("0123456789") != std::string::npos)
    return -1;
  return std::stoll(name);
}

std::vector<std::size_t> FrameSource::indices(const FrameRange& range) const {
  // The range counts frame numbers (the files' names), which skip the frames a sequence lacks.
  // A last frame beyond the sequence is an error, as in msf_integrate: clamping it ran fewer
  // frames than asked without a word.
  if (size() == 0)
    throw InvalidInputError("'" + description() + "' has no frames");
  const auto number = [&](std::size_t i) {
    const long long n = frameNumber(frameName(i));
    return n >= 0 ? n : static_cast<long long>(i);
  };
  const long long last_number = number(size() - 1);
  const std::string frames =
      std::to_string(size()) + " frames, " + frameName(0) + ".." + frameName(size() - 1);
  const std::string asked =
      std::to_string(range.first) + ":" + (range.last < 0 ? std::string() : std::to_string(range.last));
  if (range.first > last_number)
    throw InvalidInputError("frame range " + asked + " selects no frame of '" + description() + "' (" + frames + ")");
  if (range.last > last_number)
    throw InvalidInputError("frame range " + asked + " goes beyond the last frame of '" + description() + "' (" +
                            frames + ")");
  const long long last = range.last < 0 ? last_number : range.last;
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < size(); ++i)
    if (number(i) >= range.first && number(i) <= last)
      out.push_back(i);
  if (out.empty())
    throw InvalidInputError("frame range " + asked + " selects no frame of '" + description() + "' (" + frames + ")");
  return out;
}

} // namespace msf
