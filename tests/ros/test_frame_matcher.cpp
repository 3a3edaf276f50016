// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Frames of sensors that stamp apart: each scan with its nearest images, within a tolerance.
#include <msf/ros/frame_matcher.h>

#include <gtest/gtest.h>

namespace {

constexpr std::int64_t kMs = 1000000;

TEST(FrameMatcher, EachScanTakesTheNearestImagesWithinTheTolerance) {
  // Scans at 0, 100, 200, 300 ms; the right camera lags by 2-4 ms, the left has no image near 200 ms.
  const std::vector<std::int64_t> scans{0, 100 * kMs, 200 * kMs, 300 * kMs};
  const std::vector<std::int64_t> left{1 * kMs, 99 * kMs, 260 * kMs, 301 * kMs};
  const std::vector<std::int64_t> right{2 * kMs, 103 * kMs, 204 * kMs, 304 * kMs};
  const msf::FrameMatches m = msf::matchFrames(scans, left, right, {}, 50 * kMs);
  ASSERT_EQ(m.frames.size(), 3u);
  EXPECT_EQ(m.frames[0].scan, 0u);
  EXPECT_EQ(m.frames[1].left, 1u);
  EXPECT_EQ(m.frames[1].right, 1u);
  EXPECT_EQ(m.frames[2].scan, 3u);
  EXPECT_EQ(m.frames[2].left, 3u);
  EXPECT_EQ(m.frames[2].color, -1);
  ASSERT_EQ(m.notes.size(), 3u);
  EXPECT_EQ(m.notes[0], "1 scan skipped: no left image within 50 ms (at 0.200 s)");
  EXPECT_EQ(m.notes[1], "1 left image in no frame");
  EXPECT_EQ(m.notes[2], "1 right image in no frame");
}

TEST(FrameMatcher, APairWhoseImagesLieApartIsNoted) {
  // The right camera 30 ms after the left (not triggered together): matched, and said.
  const std::vector<std::int64_t> scans{0, 100 * kMs, 200 * kMs};
  const std::vector<std::int64_t> left{0, 100 * kMs, 200 * kMs};
  const std::vector<std::int64_t> right{30 * kMs, 130 * kMs, 230 * kMs};
  msf::FrameMatches m = msf::matchFrames(scans, left, right, {}, 50 * kMs);
  ASSERT_EQ(m.frames.size(), 3u);
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_EQ(m.notes[0], "the stereo pair's images lie a median of 30 ms apart: a pair must be taken at one instant "
                        "(its cameras triggered together), else a moving rig's depth is wrong");
  // 4 ms apart: no note.
  m = msf::matchFrames(scans, left, {4 * kMs, 104 * kMs, 204 * kMs}, {}, 50 * kMs);
  EXPECT_TRUE(m.notes.empty());
}

TEST(FrameMatcher, ThePairsGapIsJudgedByItsMedian) {
  // The node's live pairs: one late pair among on-time ones is no note, most pairs late are.
  EXPECT_EQ(msf::stereoPairApartNote({0, 0, 40 * kMs}), "");
  EXPECT_EQ(msf::stereoPairApartNote({10 * kMs, 10 * kMs}), ""); // at the limit: together
  EXPECT_EQ(msf::stereoPairApartNote({12 * kMs, 0, 12 * kMs}).rfind("the stereo pair's images lie a median of 12 ms", 0),
            0u);
  EXPECT_EQ(msf::stereoPairApartNote({}), "");
}

TEST(FrameMatcher, AnImageServesOnlyItsNearestScan) {
  // A LiDAR at 20 Hz and cameras at 10 Hz: every other scan has no image of its own.
  const std::vector<std::int64_t> scans{0, 50 * kMs, 100 * kMs, 150 * kMs};
  const std::vector<std::int64_t> images{10 * kMs, 110 * kMs};
  const msf::FrameMatches m = msf::matchFrames(scans, images, images, images, 60 * kMs);
  ASSERT_EQ(m.frames.size(), 2u);
  EXPECT_EQ(m.frames[0].scan, 0u);
  EXPECT_EQ(m.frames[1].scan, 2u);
  EXPECT_EQ(m.frames[1].color, 1);
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_EQ(m.notes[0], "2 scans skipped: the left image nearest to them is nearer another scan (at 0.050 s, 0.150 s)");
}

TEST(FrameMatcher, AFrameWithoutItsColourImageIsKeptAndSaidSo) {
  const std::vector<std::int64_t> scans{0, 100 * kMs};
  const msf::FrameMatches m = msf::matchFrames(scans, scans, scans, {100 * kMs}, 10 * kMs);
  ASSERT_EQ(m.frames.size(), 2u);
  EXPECT_EQ(m.frames[0].color, -1);
  EXPECT_EQ(m.frames[1].color, 0);
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_EQ(m.notes[0], "1 frame without a colour image within 10 ms: coloured from the left grey image (at 0.000 s)");
}

TEST(FrameMatcher, NoScanNoFrame) {
  EXPECT_TRUE(msf::matchFrames({}, {1}, {1}, {}, kMs).frames.empty());
  EXPECT_TRUE(msf::matchFrames({5}, {}, {5}, {}, kMs).frames.empty());
}

} // namespace
