// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace msf {

/// Frames of a recording whose sensors stamp their messages apart: each scan is a frame with
/// the left, right and colour images nearest to it in time, within a tolerance. An image
/// serves one scan, the nearest. What is left out is said, with the reason.
struct FrameMatch {
  std::size_t scan = 0, left = 0, right = 0; ///< positions in the stamp lists given
  std::ptrdiff_t color = -1;                 ///< -1: no colour image within the tolerance
};

struct FrameMatches {
  std::vector<FrameMatch> frames; ///< in the scans' order
  /// What was left out and why, one line each ("2 scans skipped: no right image within 50 ms
  /// (at 12.300 s, 13.400 s)"); times from the first scan.
  std::vector<std::string> notes;
};

/// Matches sorted stamp lists (nanoseconds); `color` may be empty (no colour camera).
FrameMatches matchFrames(const std::vector<std::int64_t>& scans, const std::vector<std::int64_t>& left,
                         const std::vector<std::int64_t>& right, const std::vector<std::int64_t>& color,
                         std::int64_t max_offset_ns);

/// A note when a stereo pair's images lie apart in time: the median of |left - right| over the
/// pairs' stamps (nanoseconds) above 10 ms, their cameras not triggered together, so a moving
/// rig's depth is wrong. "" when they lie together or there are none.
std::string stereoPairApartNote(std::vector<std::int64_t> apart_ns);

} // namespace msf
