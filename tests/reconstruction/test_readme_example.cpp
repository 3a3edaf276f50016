// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The integration example of docs/library.md, compiled from the document itself:
// tests/CMakeLists.txt copies the block between <!-- example:tsdf:begin --> and
// <!-- example:tsdf:end --> into the build tree as readme_tsdf_example.h (with #line, so
// compiler messages point into the document), and it is run here on a small synthetic
// sequence, so that the documentation cannot drift from the API.
#include "readme_tsdf_example.h" // reconstruct(clouds, poses_txt, out_dir)

#include "scenes.h"
#include "test_support.h"

#include <msf/io/cloud_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/poses.h>
#include <msf/reconstruction/tsdf_volume.h>

using namespace msf;

TEST(ReadmeExample, IntegratesCloudsAndWritesMeshAndVolume) {
  test::TempDir dir;
  const AnalyticScene scene = test::makeScene(test::SceneKind::Box);
  const PinholeCamera camera = test::smallCamera();
  Calibration calibration;
  calibration.P[0] << camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0;
  PoseList poses;
  std::vector<std::string> clouds;
  for (const auto& pose : test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 10, 3)) {
    pcl::PointCloud<pcl::PointXYZRGB> cloud;
    depthImageToCloud(scene.renderDepth(camera, pose, 20.0), calibration, 0, cloud);
    clouds.push_back(dir.file("cloud" + std::to_string(clouds.size()) + ".pcd"));
    saveCloud(clouds.back(), cloud);
    poses.push_back(pose);
  }
  saveOdometryPoses(dir.file("poses.txt"), poses);
  reconstruct(clouds, dir.file("poses.txt"), dir.path());
  pcl::PolygonMesh mesh;
  loadMesh(dir.file("mesh.ply"), mesh);
  EXPECT_GT(mesh.polygons.size(), 500u);
  EXPECT_GT(TsdfVolume::load(dir.file("volume.pcd")).numObservedVoxels(), 1000u);
}
