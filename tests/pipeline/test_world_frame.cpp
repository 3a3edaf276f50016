// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Outputs in a z-up world are the camera-world outputs rotated; poses go out and come back in
// TUM's format as well as KITTI's.
#include <msf/io/cloud_io.h>
#include <msf/io/poses.h>
#include <msf/io/tum_poses.h>
#include <msf/io/world_frame.h>
#include <msf/reconstruction/streaming_map.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <pcl/conversions.h>
#include <pcl/kdtree/kdtree_flann.h>

#include <algorithm>
#include <cmath>

namespace {

std::vector<Eigen::Vector3f> verticesOf(const std::string& ply) {
  pcl::PolygonMesh mesh;
  msf::loadMesh(ply, mesh);
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(mesh.cloud, points);
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : points)
    out.push_back(p.getVector3fMap());
  return out;
}

} // namespace

TEST_F(PipelineTest, AZUpWorldIsTheCameraWorldRotated) {
  msf::test::TempDir dir;
  for (const char* world : {"camera", "z_up"}) {
    const auto r = msf::test::runTool("msf_reconstruct", dataset() + " -frames 0:1 -panels 0 -world " + world +
                                                            " -o " + dir.file(world));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const Eigen::Isometry3d T = msf::outputTransform(msf::WorldFrame::ZUp);
  // The camera looks along +z and its image's down is +y: in the z-up world, forward and down.
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitY()).isApprox(-Eigen::Vector3d::UnitZ()));
  const auto camera = verticesOf(dir.file("camera/mesh.ply")), z_up = verticesOf(dir.file("z_up/mesh.ply"));
  ASSERT_EQ(camera.size(), z_up.size());
  ASSERT_GT(camera.size(), 1000u);
  for (std::size_t k = 0; k < camera.size(); ++k)
    ASSERT_TRUE((T.cast<float>() * camera[k]).isApprox(z_up[k], 1e-6f)) << "vertex " << k;
  const msf::PoseList a = msf::loadOdometryPoses(dir.file("camera/poses.txt"));
  const msf::PoseList b = msf::loadOdometryPoses(dir.file("z_up/poses.txt"));
  ASSERT_EQ(a.size(), 2u);
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_TRUE((T * a[i]).isApprox(b[i], 1e-8)) << i;
  // The street's road lies below its camera in the z-up world: most vertices have z < 0.
  std::size_t below = 0;
  for (const auto& v : z_up)
    below += v.z() < 0.f;
  EXPECT_GT(below, z_up.size() / 2);
  EXPECT_NE(msf::test::runTool("msf_reconstruct", dataset() + " -world up -o " + dir.file("x")).err.find(
                "world frame must be camera"),
            std::string::npos);

  // Poses in a world that is already z-up (a map frame's): -world z_up leaves it, and the outputs
  // are those of the camera world turned (the mesh to the voxel grid's turn: the map's grid is
  // the world's).
  EXPECT_TRUE(msf::worldIsZUp(T * a[0]));
  EXPECT_FALSE(msf::worldIsZUp(a[0]));
  EXPECT_TRUE(msf::outputTransform(msf::WorldFrame::ZUp, T * a[0]).matrix().isIdentity());
  msf::saveOdometryPoses(dir.file("map_poses.txt"), msf::transformPoses(a, T));
  const auto r = msf::test::runTool("msf_reconstruct", dataset() + " -frames 0:1 -panels 0 -world z_up -poses " +
                                                           dir.file("map_poses.txt") + " -o " + dir.file("map"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("already z-up"), std::string::npos) << r.out;
  const msf::PoseList map_poses = msf::loadOdometryPoses(dir.file("map/poses.txt"));
  ASSERT_EQ(map_poses.size(), b.size());
  for (std::size_t i = 0; i < b.size(); ++i)
    EXPECT_TRUE(map_poses[i].isApprox(b[i], 1e-8)) << i;
  pcl::PointCloud<pcl::PointXYZ>::Ptr turned(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& v : z_up)
    turned->push_back(pcl::PointXYZ(v.x(), v.y(), v.z()));
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(turned);
  std::vector<float> distances;
  for (const auto& v : verticesOf(dir.file("map/mesh.ply"))) {
    std::vector<int> index(1);
    std::vector<float> squared(1);
    tree.nearestKSearch(pcl::PointXYZ(v.x(), v.y(), v.z()), 1, index, squared);
    distances.push_back(std::sqrt(squared[0]));
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  EXPECT_LT(distances[distances.size() / 2], 0.05) << "metres: the median distance to the turned mesh";
}

TEST_F(PipelineTest, TumPosesOutAreTheKittiPosesAndComeBackIn) {
  msf::test::TempDir dir;
  auto r = msf::test::runTool("msf_reconstruct", dataset() + " -frames 0:2 -panels 0 -o " + dir.file("a"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const msf::StampedPoses tum = msf::loadTumPoses(dir.file("a/poses_tum.txt"));
  const msf::PoseList kitti = msf::loadOdometryPoses(dir.file("a/poses.txt"));
  ASSERT_EQ(tum.poses.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_TRUE(tum.poses[i].isApprox(kitti[i], 1e-8)) << i;
  EXPECT_NEAR(tum.timestamps[2] - tum.timestamps[0], 0.2, 1e-6); // the street's 10 Hz
  // Read back with -poses (matched by time): the same map, to float rounding of the quaternions.
  r = msf::test::runTool("msf_reconstruct",
                         dataset() + " -frames 0:2 -panels 0 -poses " + dir.file("a/poses_tum.txt") + " -o " + dir.file("b"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("poses_tum.txt'"), std::string::npos) << r.out;
  const auto va = verticesOf(dir.file("a/mesh.ply")), vb = verticesOf(dir.file("b/mesh.ply"));
  EXPECT_NEAR(static_cast<double>(va.size()), static_cast<double>(vb.size()), 0.001 * static_cast<double>(va.size()));
}
