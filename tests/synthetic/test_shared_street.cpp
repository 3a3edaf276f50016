// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Several drives over one street: the same seed and street length give one static world;
// start_m and reverse place each drive in it (msf_synth -start_m, -reverse, -street_m).
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/synthetic/scene.h>
#include <msf/synthetic/synthetic_generator.h>
#include <msf/synthetic/trajectory.h>

#include <gtest/gtest.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <sstream>

namespace {

using msf::synthetic::SyntheticConfig;
using msf::synthetic::SyntheticGenerator;

SyntheticConfig drive(double start_m, bool reverse, int frames = 8) {
  SyntheticConfig c;
  c.frames = frames;
  c.seed = 5;
  c.street_length_m = 80.0;
  c.start_m = start_m;
  c.reverse = reverse;
  return c;
}

TEST(SharedStreet, DrivesOfOneSeedAndLengthShareTheStaticWorld) {
  const SyntheticGenerator a(drive(0, false)), b(drive(30, false, 20)), c(drive(70, true));
  const auto& pa = a.scene().primitives;
  ASSERT_GT(pa.size(), 100u);
  for (const SyntheticGenerator* other : {&b, &c}) {
    const auto& po = other->scene().primitives;
    ASSERT_EQ(po.size(), pa.size());
    for (std::size_t i = 0; i < pa.size(); i += 17)
      EXPECT_TRUE(pa[i].center.x == po[i].center.x && pa[i].center.z == po[i].center.z) << "solid " << i;
    // gt/scene.ply is the world's, not the drive's.
    const pcl::PolygonMesh ma = a.mesh(), mo = other->mesh();
    pcl::PointCloud<pcl::PointXYZ> va, vo;
    pcl::fromPCLPointCloud2(ma.cloud, va);
    pcl::fromPCLPointCloud2(mo.cloud, vo);
    ASSERT_EQ(va.size(), vo.size());
    ASSERT_EQ(ma.polygons.size(), mo.polygons.size());
    for (std::size_t i = 0; i < va.size(); i += 13)
      EXPECT_TRUE(va[i].getVector3fMap() == vo[i].getVector3fMap()) << "vertex " << i;
  }
  // Without a street length, the street ends where the drive does: another world.
  SyntheticConfig own = drive(30, false, 20);
  own.street_length_m = 0.0;
  EXPECT_NE(SyntheticGenerator(own).scene().primitives.size(), pa.size());
}

TEST(SharedStreet, APlacedDriveIsTheDriveFromTheStartCarriedToItsPlace) {
  const msf::PoseList from_start = msf::synthetic::streetTrajectory(drive(0, false));
  const msf::PoseList later = msf::synthetic::streetTrajectory(drive(25, false));
  ASSERT_EQ(later.size(), from_start.size());
  for (std::size_t i = 0; i < later.size(); ++i) {
    EXPECT_TRUE(later[i].linear().isApprox(from_start[i].linear(), 1e-12));
    EXPECT_NEAR((later[i].translation() - from_start[i].translation() - Eigen::Vector3d(0, 0, 25)).norm(), 0, 1e-12);
  }
  // Reversed: from 70 m towards the start, heading -z, in the left-hand lane.
  const msf::PoseList back = msf::synthetic::streetTrajectory(drive(70, true));
  const msf::synthetic::StreetLayout layout;
  EXPECT_NEAR(back.front().translation().z(), 70.0, 1e-12);
  EXPECT_NEAR(back.back().translation().z(), 63.0, 1e-9);
  EXPECT_NEAR(back.front().translation().x(), layout.leftLaneX(), 1e-6);
  EXPECT_LT((back.front().linear() * Eigen::Vector3d::UnitZ()).z(), -0.99);
  // The drive from the start is as it always was: frame 0 is the world's origin.
  EXPECT_TRUE(from_start.front().isApprox(Eigen::Isometry3d::Identity()));
}

TEST(SharedStreet, TheCarAheadOfAReversedDriveIsAheadOfIt) {
  SyntheticConfig c = drive(70, true);
  c.moving_cars_ahead = 1;
  c.moving_cars_oncoming = 0;
  const SyntheticGenerator g(c);
  ASSERT_EQ(g.scene().movers.size(), 1u);
  const auto origin = g.scene().movers.front().originAt(0.0);
  const Eigen::Vector3d car(origin.x, origin.y, origin.z);
  const Eigen::Isometry3d& camera = g.poses().front();
  const Eigen::Vector3d ahead = camera.inverse() * car; // in the camera's frame: z forward, x right
  EXPECT_GT(ahead.z(), 8.0);
  EXPECT_LT(std::abs(ahead.x()), 1.0) << "in the camera's lane";
}

TEST(SharedStreet, ADriveOffTheStreetIsAClearError) {
  // Reversed from 5 m for 8 frames: below the street's start.
  std::string e = msf::test::errorOf([] { SyntheticGenerator(drive(5, true)); });
  EXPECT_NE(e.find("synthetic.start_m"), std::string::npos) << e;
  // Beyond the street's length.
  e = msf::test::errorOf([] { SyntheticGenerator(drive(78, false)); });
  EXPECT_NE(e.find("synthetic.street_length_m"), std::string::npos) << e;
  // The placement is printed with the rest, so gt/synthetic.yaml reproduces the drive.
  std::ostringstream plain, placed;
  msf::printConfig(plain, SyntheticConfig());
  msf::printConfig(placed, drive(25, true));
  EXPECT_NE(plain.str().find("  reverse: false\n"), std::string::npos) << plain.str();
  EXPECT_NE(placed.str().find("  start_m: 25.0\n"), std::string::npos) << placed.str();
  EXPECT_NE(placed.str().find("  reverse: true\n"), std::string::npos) << placed.str();
}

} // namespace
