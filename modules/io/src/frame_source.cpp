#include <msf/common/exceptions.h>
#include <msf/io/frame_source.h>

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
      throw InvalidInputError("frame range '" + text + "' is not 'a:b' with whole numbers a <= b");
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
    throw InvalidInputError("frame range '" + text + "' ends before it starts");
  return r;
}

const PoseList& FrameSource::poses() const {
  static const PoseList none;
  return none;
}

std::vector<std::size_t> FrameSource::indices(const FrameRange& range) const {
  // A last frame beyond the sequence is an error, as in msf_integrate: clamping it ran
  // fewer frames than asked without a word.
  if (range.first >= static_cast<int>(size()))
    throw InvalidInputError("frame range " + std::to_string(range.first) + ":" +
                            (range.last < 0 ? std::string() : std::to_string(range.last)) + " selects no frame of '" +
                            description() + "' (" + std::to_string(size()) + " frames)");
  if (range.last >= static_cast<int>(size()))
    throw InvalidInputError("frame range " + std::to_string(range.first) + ":" + std::to_string(range.last) +
                            " goes beyond the last frame of '" + description() + "' (" + std::to_string(size()) +
                            " frames, 0:" + std::to_string(size() - 1) + ")");
  const int last = range.last < 0 ? static_cast<int>(size()) - 1 : range.last;
  std::vector<std::size_t> out;
  for (int i = range.first; i <= last; ++i)
    out.push_back(static_cast<std::size_t>(i)); // not empty: FrameRange::parse orders first <= last
  return out;
}

} // namespace msf
