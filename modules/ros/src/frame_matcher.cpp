// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/ros/frame_matcher.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>

namespace msf {

namespace {

constexpr std::ptrdiff_t kNone = -1;  // no image within the tolerance
constexpr std::ptrdiff_t kTaken = -2; // the image within it is nearer another scan

/// For each scan, the position of the nearest image within `max_offset_ns`, an image kept by
/// its nearest scan only (kTaken for the others), or kNone.
std::vector<std::ptrdiff_t> nearestImages(const std::vector<std::int64_t>& scans,
                                          const std::vector<std::int64_t>& images, std::int64_t max_offset_ns) {
  std::vector<std::ptrdiff_t> pick(scans.size(), kNone);
  std::map<std::ptrdiff_t, std::size_t> owner; // image -> its nearest scan so far
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const auto after = std::lower_bound(images.begin(), images.end(), scans[s]);
    std::ptrdiff_t best = kNone;
    std::int64_t best_offset = max_offset_ns + 1;
    for (auto it : {after, after == images.begin() ? images.end() : after - 1})
      if (it != images.end() && std::llabs(*it - scans[s]) < best_offset) {
        best = it - images.begin();
        best_offset = std::llabs(*it - scans[s]);
      }
    if (best == kNone)
      continue;
    pick[s] = best;
    const auto [it, first] = owner.emplace(best, s);
    if (first)
      continue;
    const std::size_t other = it->second;
    if (std::llabs(images[best] - scans[other]) <= best_offset) {
      pick[s] = kTaken;
    } else {
      pick[other] = kTaken;
      it->second = s;
    }
  }
  return pick;
}

std::string seconds(std::int64_t ns) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f s", static_cast<double>(ns) * 1e-9);
  return text;
}

/// "3 scans skipped: <why> (at 0.300 s, 0.400 s, ...)", the first few times.
std::string listed(const std::string& head, const std::vector<std::int64_t>& times) {
  constexpr std::size_t kShown = 5;
  std::string text = head + " (at ";
  for (std::size_t k = 0; k < times.size() && k < kShown; ++k)
    text += (k ? ", " : "") + seconds(times[k]);
  return text + (times.size() > kShown ? ", ...)" : ")");
}

/// The note of stereoPairApartNote over the matched pairs. Past half a frame's period the left
/// image meets the right of another frame, so the median read is at most half the period.
std::string pairApart(const std::vector<FrameMatch>& frames, const std::vector<std::int64_t>& left,
                      const std::vector<std::int64_t>& right) {
  std::vector<std::int64_t> apart;
  for (const FrameMatch& m : frames)
    apart.push_back(std::llabs(left[m.left] - right[m.right]));
  return stereoPairApartNote(std::move(apart));
}

std::string plural(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

} // namespace

std::string stereoPairApartNote(std::vector<std::int64_t> apart_ns) {
  constexpr std::int64_t kPairApart = 10 * 1000000;
  if (apart_ns.empty())
    return "";
  const auto middle = apart_ns.begin() + static_cast<std::ptrdiff_t>(apart_ns.size() / 2);
  std::nth_element(apart_ns.begin(), middle, apart_ns.end());
  if (*middle <= kPairApart)
    return "";
  return "the stereo pair's images lie a median of " + std::to_string(*middle / 1000000) +
         " ms apart: a pair must be taken at one instant (its cameras triggered together), else a moving rig's "
         "depth is wrong";
}

FrameMatches matchFrames(const std::vector<std::int64_t>& scans, const std::vector<std::int64_t>& left,
                         const std::vector<std::int64_t>& right, const std::vector<std::int64_t>& color,
                         std::int64_t max_offset_ns) {
  FrameMatches result;
  const std::int64_t origin = scans.empty() ? 0 : scans.front();
  const std::string within = "within " + std::to_string(max_offset_ns / 1000000) + " ms";
  const struct Camera {
    const char* name;
    std::vector<std::ptrdiff_t> pick;
    std::size_t images;
  } cameras[] = {{"left", nearestImages(scans, left, max_offset_ns), left.size()},
                 {"right", nearestImages(scans, right, max_offset_ns), right.size()},
                 {"colour", nearestImages(scans, color, max_offset_ns), color.size()}};

  std::map<std::string, std::vector<std::int64_t>> skipped; // reason -> scan times
  std::vector<std::int64_t> uncoloured;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    std::string reason;
    for (int c = 0; c < 2 && reason.empty(); ++c)
      if (cameras[c].pick[s] < 0)
        reason = cameras[c].pick[s] == kNone ? std::string("no ") + cameras[c].name + " image " + within
                                             : std::string("the ") + cameras[c].name + " image nearest to them is " +
                                                   "nearer another scan";
    if (!reason.empty()) {
      skipped[reason].push_back(scans[s] - origin);
      continue;
    }
    FrameMatch match{s, static_cast<std::size_t>(cameras[0].pick[s]), static_cast<std::size_t>(cameras[1].pick[s]),
                     cameras[2].pick[s] >= 0 ? cameras[2].pick[s] : -1};
    if (!color.empty() && match.color < 0)
      uncoloured.push_back(scans[s] - origin);
    result.frames.push_back(match);
  }
  for (const auto& [reason, times] : skipped)
    result.notes.push_back(listed(plural(times.size(), "scan") + " skipped: " + reason, times));
  if (const std::string apart = pairApart(result.frames, left, right); !apart.empty())
    result.notes.push_back(apart);
  if (!uncoloured.empty())
    result.notes.push_back(listed(plural(uncoloured.size(), "frame") + " without a colour image " + within +
                                      ": coloured from the left grey image",
                                  uncoloured));
  for (const Camera& camera : cameras) {
    std::vector<bool> used(camera.images, false);
    for (const FrameMatch& m : result.frames) {
      const std::ptrdiff_t k = &camera == &cameras[0] ? static_cast<std::ptrdiff_t>(m.left)
                               : &camera == &cameras[1] ? static_cast<std::ptrdiff_t>(m.right)
                                                        : m.color;
      if (k >= 0)
        used[static_cast<std::size_t>(k)] = true;
    }
    const auto unused = static_cast<std::size_t>(std::count(used.begin(), used.end(), false));
    if (unused > 0)
      result.notes.push_back(plural(unused, std::string(camera.name) + " image") + " in no frame");
  }
  return result;
}

} // namespace msf
