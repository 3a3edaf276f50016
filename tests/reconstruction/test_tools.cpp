#include "scenes.h"
#include "test_support.h"

#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/poses.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace msf;

namespace {

/// Three depth clouds of the sphere scene with their poses and calibration, as files.
struct SphereFiles {
  test::TempDir dir;
  std::vector<std::string> clouds;
  AnalyticScene scene = test::makeScene(test::SceneKind::Sphere);
  SphereFiles() {
    const PinholeCamera camera = test::smallCamera();
    Calibration calibration;
    for (auto& P : calibration.P)
      P << camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0;
    calibration.P[1](0, 3) = -camera.fx * 0.5;
    calibration.image_size = cv::Size(camera.width, camera.height);
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
  // So does a piece size above the whole sphere's, with its own message.
  r = test::runTool("msf_mesh", volume + " " + f.dir.file("out/empty.ply") + " -min_component_triangles 100000000");
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
  expectToolError(test::runTool("msf_mesh", dir.file("plain.pcd") + " " + dir.file("mesh.ply") +
                                                " -min_component_triangles -1"),
                  "msf_mesh", "marching_cubes.min_component_triangles must be >= 0");
  expectToolError(test::runTool("msf_mesh", dir.file("plain.pcd") + " " + dir.file("mesh.ply") +
                                                " -min_component_triangles 2O"),
                  "msf_mesh", "-min_component_triangles needs a whole number, not '2O'");
  std::ofstream(dir.file("typo.yaml")) << "%YAML:1.0\nmarching_cubes:\n  min_weigth: 2\n";
  expectToolError(test::runTool("msf_mesh", dir.file("plain.pcd") + " " + dir.file("mesh.ply") + " -config " +
                                                dir.file("typo.yaml")),
                  "msf_mesh", "'marching_cubes.min_weigth' is not a key of section 'marching_cubes'");
  EXPECT_FALSE(test::fileExists(dir.file("mesh.ply")));
}
