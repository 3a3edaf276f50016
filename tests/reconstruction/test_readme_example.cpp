// The library example of the README's reconstruction section, compiled and run here on a
// small synthetic sequence so that the README cannot drift from the API.
#include "scenes.h"
#include "test_support.h"

#include <msf/io/cloud_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/poses.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

namespace {

void readmeExample(const std::vector<std::string>& clouds, const std::string& poses_txt, const std::string& out_dir) {
  // --- README example begins ---
  msf::TsdfVolume volume(0.1, 0.3);                 // voxel size and truncation, metres
  msf::TsdfIntegrator::Config config;
  config.lambda = 5;                                // eq. 7; 0 = plain weighted mean
  msf::TsdfIntegrator integrator(volume, config);
  const msf::PoseList poses = msf::loadOdometryPoses(poses_txt); // T_world_cam, one per cloud
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    pcl::PointCloud<pcl::PointXYZRGB> cloud;        // organized, camera frame, NaN = no depth
    msf::loadCloud(clouds[i], cloud);
    integrator.integrate(cloud, poses[i]);          // intrinsics recovered from the cloud
  }
  pcl::PolygonMesh mesh;
  msf::MarchingCubes().extract(volume, mesh);       // welded, coloured
  msf::saveMesh(out_dir + "/mesh.ply", mesh);
  volume.save(out_dir + "/volume.pcd");             // msf_mesh reads it
  // --- README example ends ---
}

} // namespace

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
  readmeExample(clouds, dir.file("poses.txt"), dir.path());
  pcl::PolygonMesh mesh;
  loadMesh(dir.file("mesh.ply"), mesh);
  EXPECT_GT(mesh.polygons.size(), 500u);
  EXPECT_GT(TsdfVolume::load(dir.file("volume.pcd")).numObservedVoxels(), 1000u);
}
