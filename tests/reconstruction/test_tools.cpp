// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"
#include "test_support.h"

#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/poses.h>
#include <msf/io/velodyne_io.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <utility>

using namespace msf;

namespace {

/// test::smallCamera as a stereo rig (0.5 m baseline) with the LiDAR at the camera.
Calibration smallCalibration() {
  const PinholeCamera camera = test::smallCamera();
  Calibration calibration;
  for (auto& P : calibration.P)
    P << camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0;
  calibration.P[1](0, 3) = -camera.fx * 0.5;
  calibration.image_size = cv::Size(camera.width, camera.height);
  return calibration;
}

/// Three depth clouds of the sphere scene with their poses and calibration, as files.
struct SphereFiles {
  test::TempDir dir;
  std::vector<std::string> clouds;
  AnalyticScene scene = test::makeScene(test::SceneKind::Sphere);
  SphereFiles() {
    const PinholeCamera camera = test::smallCamera();
    const Calibration calibration = smallCalibration();
    saveCalibrationYaml(calibration, dir.file("camera.yaml"));
    PoseList poses;
    const auto arc = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 15, 3);
    for (std::size_t i = 0; i < arc.size(); ++i) {
      pcl::PointCloud<pcl::PointXYZRGB> cloud;
      depthImageToCloud(scene.renderDepth(camera, arc[i], 20.0), calibration, 0, cloud);
      for (auto& p : cloud) {
        p.r = 40;
        p.g = 160;
        p.b = 220;
      }
      clouds.push_back(dir.file("depth_" + std::to_string(i) + ".pcd"));
      saveCloud(clouds.back(), cloud);
      poses.push_back(arc[i]);
    }
    saveOdometryPoses(dir.file("poses.txt"), poses);
    PoseList two(poses.begin(), poses.begin() + 2);
    saveOdometryPoses(dir.file("two_poses.txt"), two);
  }
  std::string cloudArgs() const {
    std::string s;
    for (const auto& c : clouds)
      s += c + " ";
    return s;
  }
};

void expectToolError(const test::CommandResult& r, const std::string& tool, const std::string& mentions) {
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(tool + ": error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(mentions), std::string::npos) << r.err;
}

} // namespace

TEST(Tools, IntegrateThenMeshTheSphere) {
  SphereFiles f;
  const std::string volume = f.dir.file("out/volume.pcd");
  std::filesystem::create_directories(f.dir.file("out"));
  auto r = test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -o " + volume +
                                              " -voxel 0.04 -trunc 0.12 -lambda 0");
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("observed voxels"), std::string::npos) << r.out;
  const TsdfVolume loaded = TsdfVolume::load(volume);
  EXPECT_DOUBLE_EQ(loaded.voxelSize(), 0.04);

  // -calib and -input_dir give the same volume.
  const std::string volume2 = f.dir.file("out/volume2.pcd");
  std::filesystem::create_directories(f.dir.file("in"));
  for (std::size_t i = 0; i < f.clouds.size(); ++i)
    std::filesystem::copy_file(f.clouds[i], f.dir.file("in/" + std::to_string(i) + ".pcd"));
  r = test::runTool("msf_integrate", "-input_dir " + f.dir.file("in") + " -poses " + f.dir.file("poses.txt") +
                                         " -calib " + f.dir.file("camera.yaml") + " -o " + volume2 +
                                         " -voxel 0.04 -trunc 0.12");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(TsdfVolume::load(volume2).numObservedVoxels(), loaded.numObservedVoxels());

  for (const char* name : {"mesh.ply", "mesh.obj", "mesh.vtk"}) {
    const std::string mesh_path = f.dir.file(std::string("out/") + name);
    r = test::runTool("msf_mesh", volume + " " + mesh_path);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    pcl::PolygonMesh mesh;
    loadMesh(mesh_path, mesh);
    ASSERT_GT(mesh.polygons.size(), 1000u) << name;
    pcl::PointCloud<pcl::PointXYZ> vertices;
    pcl::fromPCLPointCloud2(mesh.cloud, vertices);
    double sum = 0;
    for (const auto& p : vertices)
      sum += std::abs(f.scene.signedDistance(Eigen::Vector3d(p.x, p.y, p.z)));
    EXPECT_LE(sum / static_cast<double>(vertices.size()), 0.1 * 0.04) << name;
  }
  // A volume rewritten by PCL loses its header comment: msf_mesh names the way out, and
  // meshes it given -voxel and -trunc.
  {
    pcl::PCLPointCloud2 blob;
    loadCloudBlob(volume, blob);
    pcl::io::savePCDFile(f.dir.file("out/rewritten.pcd"), blob, Eigen::Vector4f::Zero(),
                         Eigen::Quaternionf::Identity(), true);
    r = test::runTool("msf_mesh", f.dir.file("out/rewritten.pcd") + " " + f.dir.file("out/r.ply"));
    expectToolError(r, "msf_mesh", "-voxel V -trunc T");
    r = test::runTool("msf_mesh", f.dir.file("out/rewritten.pcd") + " " + f.dir.file("out/r.ply") +
                                      " -voxel 0.04 -trunc 0.12");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    pcl::PolygonMesh rewritten, original;
    loadMesh(f.dir.file("out/r.ply"), rewritten);
    loadMesh(f.dir.file("out/mesh.ply"), original);
    EXPECT_EQ(rewritten.polygons.size(), original.polygons.size());
  }
  // A minimum weight above every voxel's leaves no surface: an error, and no file.
  r = test::runTool("msf_mesh", volume + " " + f.dir.file("out/empty.ply") + " -min_weight 1e6");
  expectToolError(r, "msf_mesh", "no surface");
  EXPECT_FALSE(test::fileExists(f.dir.file("out/empty.ply")));
  // So does a piece size above the whole sphere's, with its own message (the sphere, known to 5 cm,
  // would be kept for its weight but for -component_keep_weight 0).
  r = test::runTool("msf_mesh", volume + " " + f.dir.file("out/empty.ply") +
                                    " -min_component_triangles 100000000 -component_keep_weight 0");
  expectToolError(r, "msf_mesh", "every piece of its surface has fewer than 100000000 triangles");
  EXPECT_FALSE(test::fileExists(f.dir.file("out/empty.ply")));
}

TEST(Tools, IntegrateRejectsBadInputAndLeavesNoFile) {
  SphereFiles f;
  std::filesystem::create_directories(f.dir.file("out"));
  const std::string out = f.dir.file("out/volume.pcd");
  // Pose count not matching.
  expectToolError(test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("two_poses.txt") + " -o " + out),
                  "msf_integrate", "3 depth clouds but 2 poses");
  // -frames selects poses; out of range is an error.
  expectToolError(test::runTool("msf_integrate",
                                f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -frames 1:5 -o " + out),
                  "msf_integrate", "beyond");
  // Voxel size <= 0.
  expectToolError(test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -o " + out +
                                                     " -voxel 0"),
                  "msf_integrate", "voxel size");
  expectToolError(test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -o " + out +
                                                     " -voxel -0.1"),
                  "msf_integrate", "voxel size");
  // An unorganized cloud.
  pcl::PointCloud<pcl::PointXYZ> scan;
  for (int i = 0; i < 50; ++i)
    scan.push_back(pcl::PointXYZ(0.1f * i, 0.f, 3.f));
  saveCloud(f.dir.file("scan.pcd"), scan);
  expectToolError(test::runTool("msf_integrate", f.dir.file("scan.pcd") + " -poses " + f.dir.file("two_poses.txt") +
                                                     " -frames 0:0 -o " + out),
                  "msf_integrate", "not organized");
  // Unknown option, missing file, bad weighting.
  expectToolError(test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -o " + out +
                                                     " -voxle 0.1"),
                  "msf_integrate", "-voxle");
  expectToolError(test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("nope.txt") + " -o " + out),
                  "msf_integrate", "nope.txt");
  expectToolError(test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -o " + out +
                                                     " -weighting cubic"),
                  "msf_integrate", "cubic");
  expectToolError(test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -o " + out +
                                                     " -carving -no_carving"),
                  "msf_integrate", "choose one");
  EXPECT_EQ(test::countEntries(f.dir.file("out")), 0u);
  // -no_carving turns off what is on by default: the printed configuration says so.
  const auto r = test::runTool("msf_integrate", f.cloudArgs() + "-poses " + f.dir.file("poses.txt") + " -o " + out +
                                                    " -no_carving -print_config");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("space_carving: false"), std::string::npos) << r.out;
}

TEST(Tools, IntegrateWithScansClearsWhatMovedAwayOutOfTheCamerasView) {
  // Frame 0 sees a patch 4 m ahead. Frame 1, from the same place turned round, does not see it,
  // but its LiDAR scan (returns 15 m away all around) passes through where the patch was: with
  // -scans the patch is carved away, as msf_reconstruct's scan carving does; without, it stays.
  test::TempDir dir;
  const PinholeCamera camera = test::smallCamera();
  Calibration calibration = smallCalibration();
  // KITTI's axes: the LiDAR's x (forward) is the camera's z, its y (left) -x, its z (up) -y.
  calibration.T_cam0_velo.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  saveCalibrationYaml(calibration, dir.file("camera.yaml"));

  cv::Mat patch(camera.height, camera.width, CV_32FC1, cv::Scalar(0.f));
  patch(cv::Rect(camera.width / 2 - 40, camera.height / 2 - 40, 80, 80)).setTo(4.f);
  const cv::Mat wall(camera.height, camera.width, CV_32FC1, cv::Scalar(8.f));
  PoseList poses(2, Eigen::Isometry3d::Identity());
  poses[1].linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  saveOdometryPoses(dir.file("poses.txt"), poses);
  std::string clouds;
  for (int i = 0; i < 2; ++i) {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    depthImageToCloud(i == 0 ? patch : wall, calibration, 0, cloud);
    saveCloud(dir.file("depth_" + std::to_string(i) + ".pcd"), cloud);
    clouds += dir.file("depth_" + std::to_string(i) + ".pcd") + " ";
  }
  // Returns 15 m away at -10..10 degrees of elevation all around; scan 0 none ahead (the patch
  // is there, inside the camera's view, where scans do not carve).
  std::filesystem::create_directories(dir.file("scans"));
  for (int i = 0; i < 2; ++i) {
    pcl::PointCloud<pcl::PointXYZI> scan;
    for (double el = -10.0; el <= 10.0; el += 0.4)
      for (double az = -180.0; az < 180.0; az += 0.2) {
        if (i == 0 && std::abs(az) < 40.0)
          continue;
        const double e = el * M_PI / 180.0, a = az * M_PI / 180.0;
        pcl::PointXYZI p;
        p.x = static_cast<float>(15.0 * std::cos(e) * std::cos(a));
        p.y = static_cast<float>(15.0 * std::cos(e) * std::sin(a));
        p.z = static_cast<float>(15.0 * std::sin(e));
        p.intensity = 0.5f;
        scan.push_back(p);
      }
    saveVelodyneBin(dir.file("scans/" + std::to_string(i) + ".bin"), scan);
  }

  const std::string common = clouds + "-poses " + dir.file("poses.txt") + " -calib " + dir.file("camera.yaml");
  auto patchVertices = [&](const std::string& volume) {
    TriangleMesh mesh;
    MarchingCubes().extract(TsdfVolume::load(volume), mesh);
    std::size_t n = 0;
    for (const auto& v : mesh.vertices)
      n += std::abs(v.x()) < 0.5f && std::abs(v.y()) < 0.5f && std::abs(v.z() - 4.f) < 0.3f;
    return n;
  };
  auto r = test::runTool("msf_integrate", common + " -o " + dir.file("plain.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::runTool("msf_integrate", common + " -scans " + dir.file("scans") + " -o " + dir.file("carved.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::size_t plain = patchVertices(dir.file("plain.pcd")), carved = patchVertices(dir.file("carved.pcd"));
  std::printf("  patch vertices: %zu without the scans, %zu with them\n", plain, carved);
  EXPECT_GT(plain, 50u); // the 1.07 m square at 0.1 m voxels
  EXPECT_EQ(carved, 0u);

  // A whole sequence's scan folder: -frames picks scan 1 for the pose of line 1.
  r = test::runTool("msf_integrate", dir.file("depth_1.pcd") + " -poses " + dir.file("poses.txt") + " -frames 1:1 -calib " +
                                         dir.file("camera.yaml") + " -scans " + dir.file("scans") + " -o " +
                                         dir.file("one.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // Bad input: a clear error, no volume.
  const std::string out = dir.file("bad.pcd");
  expectToolError(test::runTool("msf_integrate", clouds + "-poses " + dir.file("poses.txt") + " -scans " +
                                                     dir.file("scans") + " -o " + out),
                  "msf_integrate", "-scans needs -calib");
  expectToolError(test::runTool("msf_integrate", common + " -scans " + dir.file("scans") + " -no_carving -o " + out),
                  "msf_integrate", "space carving");
  std::filesystem::remove(dir.file("scans/1.bin"));
  expectToolError(test::runTool("msf_integrate", common + " -scans " + dir.file("scans") + " -o " + out),
                  "msf_integrate", "2 depth clouds but 1 scans");
  std::ofstream(dir.file("scans/1.bin"), std::ios::binary) << "truncated";
  expectToolError(test::runTool("msf_integrate", common + " -scans " + dir.file("scans") + " -o " + out),
                  "msf_integrate", "1.bin");
  expectToolError(test::runTool("msf_integrate", common + " -scans " + dir.file("nowhere") + " -o " + out),
                  "msf_integrate", "nowhere");
  EXPECT_FALSE(test::fileExists(out));
}

TEST(Tools, MeshRejectsBadInput) {
  test::TempDir dir;
  expectToolError(test::runTool("msf_mesh", dir.file("absent.pcd") + " " + dir.file("mesh.ply")), "msf_mesh",
                  "absent.pcd");
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.push_back(pcl::PointXYZ(0, 0, 0));
  saveCloud(dir.file("plain.pcd"), cloud);
  expectToolError(test::runTool("msf_mesh", dir.file("plain.pcd") + " " + dir.file("mesh.ply")), "msf_mesh",
                  "plain.pcd");
  expectToolError(test::runTool("msf_mesh", dir.file("plain.pcd") + " " + dir.file("mesh.stl")), "msf_mesh", ".stl");
  // A bad value of a mesher flag: the message names the flag or the key it sets.
  const std::pair<std::string, std::string> bad_flags[] = {
      {"-min_component_triangles -1", "marching_cubes.min_component_triangles must be >= 0"},
      {"-min_component_triangles 2O", "-min_component_triangles needs a whole number, not '2O'"},
      {"-component_keep_weight -1", "marching_cubes.component_keep_weight must be >= 0"},
      {"-component_keep_weight nan", "-component_keep_weight needs a number, not 'nan'"},
      {"-min_component_extent_voxels -1", "marching_cubes.min_component_extent_voxels must be >= 0, not -1"},
      {"-min_component_extent_voxels nan", "-min_component_extent_voxels needs a number, not 'nan'"}};
  for (const auto& [flags, message] : bad_flags)
    expectToolError(test::runTool("msf_mesh", dir.file("plain.pcd") + " " + dir.file("mesh.ply") + " " + flags),
                    "msf_mesh", message);
  EXPECT_FALSE(test::fileExists(dir.file("mesh.ply")));
  std::ofstream(dir.file("typo.yaml")) << "%YAML:1.0\nmarching_cubes:\n  min_weigth: 2\n";
  expectToolError(test::runTool("msf_mesh", dir.file("plain.pcd") + " " + dir.file("mesh.ply") + " -config " +
                                                dir.file("typo.yaml")),
                  "msf_mesh", "'marching_cubes.min_weigth' is not a key of section 'marching_cubes'");
  EXPECT_FALSE(test::fileExists(dir.file("mesh.ply")));
}
