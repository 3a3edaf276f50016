// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The limits hostile inputs are checked against.
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>

#include "test_support.h"
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

using msf::test::errorOf;

TEST(Limits, ThreadsAreCapped) {
  EXPECT_NO_THROW(msf::limits::checkThreads(0, "t"));
  EXPECT_NO_THROW(msf::limits::checkThreads(msf::limits::kMaxThreads, "t"));
  EXPECT_THROW(msf::limits::checkThreads(100000, "x.threads"), msf::ConfigError);
  EXPECT_NE(errorOf([] { msf::limits::checkThreads(-1, "x.threads (-threads)"); })
                .find("x.threads (-threads) must be 0 (all cores) .. 256, not -1"),
            std::string::npos);
}

TEST(Limits, ImageSizes) {
  EXPECT_NO_THROW(msf::limits::checkImageSize(1242, 375, "i"));
  EXPECT_THROW(msf::limits::checkImageSize(100000, 100000, "i"), msf::InvalidInputError);
  EXPECT_THROW(msf::limits::checkImageSize(0, 10, "i"), msf::InvalidInputError);
  EXPECT_NE(errorOf([] { msf::limits::checkImageSize(30000, 20000, "image 'a.png'"); }).find("image 'a.png'"),
            std::string::npos);
  // Within the side, but not the area: an 8192-wide stereo pair or an 8192x8192 projection ran
  // for minutes in gigabytes.
  EXPECT_NO_THROW(msf::limits::checkImageSize(8192, 2048, "i"));
  EXPECT_NO_THROW(msf::limits::checkImageSize(4096, 4096, "i"));
  EXPECT_EQ(errorOf([] { msf::limits::checkImageSize(8192, 2472, "image 'l.png'"); }),
            "image 'l.png': image size 8192x2472 has 20250624 pixels, more than the 16777216 (4096x4096) a frame may "
            "have: each of its stages would take gigabytes and minutes");
}

TEST(Limits, RigidTransforms) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() << 100, -5, 3;
  EXPECT_NO_THROW(msf::limits::checkRigid(T, "pose"));
  Eigen::Isometry3d scaled = T;
  scaled.linear() *= 1000.0;
  EXPECT_NE(errorOf([&] { msf::limits::checkRigid(scaled, "pose 3"); }).find("pose 3 is not a rigid transform"),
            std::string::npos);
  Eigen::Isometry3d mirrored = T;
  mirrored.linear().col(0) *= -1.0;
  EXPECT_THROW(msf::limits::checkRigid(mirrored, "pose"), msf::InvalidInputError);
  Eigen::Isometry3d far = T;
  far.translation().x() = 1e30;
  EXPECT_NE(errorOf([&] { msf::limits::checkRigid(far, "pose"); }).find("translation of 1e+30 m"), std::string::npos);
  Eigen::Isometry3d nan = T;
  nan.translation().y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(errorOf([&] { msf::limits::checkRigid(nan, "pose"); }).find("not finite"), std::string::npos);
}

TEST(Limits, CheckedRound) {
  EXPECT_EQ(msf::limits::checkedRound(2.6, 0, 10, "v"), 3);
  EXPECT_THROW(msf::limits::checkedRound(1e30, 0, 65535, "v"), msf::InvalidInputError);
  EXPECT_THROW(msf::limits::checkedRound(std::nan(""), 0, 65535, "v"), msf::InvalidInputError);
}

} // namespace
