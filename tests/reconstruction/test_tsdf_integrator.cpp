#include "scenes.h"
#include "test_support.h"

#include <msf/common/exceptions.h>
#include <msf/io/organized_conversion.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <pcl/conversions.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <cmath>

namespace msf::test {
/// A point type like the fusion stage's: x y z rgb and a per-pixel weight.
struct EIGEN_ALIGN16 PointFused {
  PCL_ADD_POINT4D;
  PCL_ADD_RGB;
  float weight;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};
} // namespace msf::test
POINT_CLOUD_REGISTER_POINT_STRUCT(msf::test::PointFused,
                                  (float, x, x)(float, y, y)(float, z, z)(float, rgb, rgb)(float, weight, weight))
#include <msf/reconstruction/impl/depth_frame.hpp>

using namespace msf;
using test::SceneKind;

namespace {

constexpr double kVoxel = 0.04;
constexpr double kTrunc = 0.12;

struct SceneResult {
  TriangleMesh mesh;
  double error = 0;    // mean |sdf| of vertices, metres
  double coverage = 0; // share of seen surface points within one voxel of a vertex
};

SceneResult reconstruct(SceneKind kind, double sigma, double lambda, int frames = 5) {
  const AnalyticScene scene = test::makeScene(kind);
  TsdfVolume volume(kVoxel, kTrunc);
  TsdfIntegrator::Config config;
  config.lambda = lambda;
  TsdfIntegrator integrator(volume, config);
  const auto camera = test::smallCamera();
  const auto poses = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 15, frames);
  for (int i = 0; i < frames; ++i)
    integrator.integrate(test::renderFrame(scene, camera, poses[i], sigma, 7 + i), poses[i]);
  SceneResult r;
  MarchingCubes().extract(volume, r.mesh);
  r.error = test::meanVertexError(scene, r.mesh);

  // Coverage of the surface the cameras saw (exact depth, every 3rd pixel).
  pcl::PointCloud<pcl::PointXYZ>::Ptr vertices(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& v : r.mesh.vertices)
    vertices->push_back(pcl::PointXYZ(v.x(), v.y(), v.z()));
  if (vertices->empty())
    return r;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(vertices);
  std::size_t seen = 0, covered = 0;
  std::vector<int> index(1);
  std::vector<float> d2(1);
  for (const auto& pose : poses) {
    const cv::Mat depth = scene.renderDepth(camera, pose, 20.0);
    for (int v = 1; v < depth.rows - 1; v += 3)
      for (int u = 1; u < depth.cols - 1; u += 3) {
        const float z = depth.at<float>(v, u);
        if (z <= 0)
          continue;
        const Eigen::Vector3d p =
            pose * Eigen::Vector3d((u - camera.cx) / camera.fx * z, (v - camera.cy) / camera.fy * z, z);
        ++seen;
        tree.nearestKSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), 1, index, d2);
        covered += d2[0] <= kVoxel * kVoxel;
      }
  }
  r.coverage = static_cast<double>(covered) / static_cast<double>(seen);
  return r;
}

} // namespace

class ExactScene : public ::testing::TestWithParam<SceneKind> {};

TEST_P(ExactScene, MeshIsWithinATenthOfAVoxelAndCoversTheSeenSurface) {
  const SceneResult r = reconstruct(GetParam(), 0.0, 0.0);
  ASSERT_GT(r.mesh.triangles.size(), 1000u);
  EXPECT_LE(r.error, 0.1 * kVoxel) << "mean vertex error " << r.error / kVoxel << " voxel";
  EXPECT_GE(r.coverage, 0.99);
  std::printf("  %zu vertices, mean error %.4f voxel, coverage %.4f\n", r.mesh.vertices.size(), r.error / kVoxel,
              r.coverage);
}

TEST_P(ExactScene, RegularizationKeepsExactSurfacesClose) {
  // Eq. 7 smooths: on exact depth it may round edges a little, never move smooth parts far.
  const SceneResult r = reconstruct(GetParam(), 0.0, 5.0);
  EXPECT_LE(r.error, 0.25 * kVoxel) << "mean vertex error " << r.error / kVoxel << " voxel";
  EXPECT_GE(r.coverage, 0.98);
}

INSTANTIATE_TEST_SUITE_P(Analytic, ExactScene, ::testing::Values(SceneKind::Plane, SceneKind::Sphere, SceneKind::Box),
                         [](const ::testing::TestParamInfo<SceneKind>& p) {
                           return std::string(p.param == SceneKind::Plane    ? "Plane"
                                              : p.param == SceneKind::Sphere ? "Sphere"
                                                                             : "Box");
                         });

TEST(TsdfIntegrator, LambdaReducesTheErrorOfNoisyDepth) {
  const double plain = reconstruct(SceneKind::Sphere, 0.03, 0.0).error;
  const double regularized = reconstruct(SceneKind::Sphere, 0.03, 5.0).error;
  std::printf("  sigma 30 mm: lambda 0 -> %.2f mm, lambda 5 -> %.2f mm\n", plain * 1e3, regularized * 1e3);
  EXPECT_LT(regularized, 0.8 * plain);
}

TEST(TsdfIntegrator, PlainWeightedMeanWithSignsAndWeights) {
  // Two fronto-parallel walls at 2.0 m and 2.1 m seen from the origin: with lambda = 0 a voxel
  // holds the mean of d - z, so the surface lies at 2.05 m; weights count the frames.
  TsdfVolume volume(0.05, 0.3);
  TsdfIntegrator integrator(volume);
  DepthFrame frame;
  frame.camera = test::smallCamera();
  frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
  integrator.integrate(frame, Eigen::Isometry3d::Identity());
  frame.depth.setTo(2.1f);
  integrator.integrate(frame, Eigen::Isometry3d::Identity());
  const TsdfVoxel* v = volume.findVoxel(GridIndex(0, 0, 40)); // (0, 0, 2.0)
  ASSERT_NE(v, nullptr);
  EXPECT_NEAR(v->sdf, 0.05f, 1e-5);
  EXPECT_FLOAT_EQ(v->weight, 2.f);
  const TsdfVoxel* behind = volume.findVoxel(GridIndex(0, 0, 44)); // 2.2 m
  ASSERT_NE(behind, nullptr);
  EXPECT_NEAR(behind->sdf, -0.15f, 1e-5);
  EXPECT_EQ(volume.findVoxel(GridIndex(0, 0, 30)), nullptr); // 1.5 m: outside the band, never allocated
  EXPECT_GT(integrator.lastStats().voxels_updated, 1000u);

  // The surface is at 2.05 m.
  TriangleMesh mesh;
  MarchingCubes().extract(volume, mesh);
  ASSERT_FALSE(mesh.vertices.empty());
  for (const auto& p : mesh.vertices)
    EXPECT_NEAR(p.z(), 2.05f, 1e-4);
}

TEST(TsdfIntegrator, WeightingModesAndMaximumWeight) {
  DepthFrame frame;
  frame.camera = test::smallCamera();
  frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
  const GridIndex at(0, 0, 40);
  {
    TsdfVolume volume(0.05, 0.3);
    TsdfIntegrator::Config c;
    c.weighting = TsdfIntegrator::Weighting::InverseSquare;
    TsdfIntegrator(volume, c).integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 0.25f);
  }
  {
    TsdfVolume volume(0.05, 0.3);
    TsdfIntegrator::Config c;
    c.max_weight = 3.f;
    TsdfIntegrator integrator(volume, c);
    for (int i = 0; i < 5; ++i)
      integrator.integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 3.f);
  }
  {
    TsdfVolume volume(0.05, 0.3);
    TsdfIntegrator::Config c;
    c.weighting = TsdfIntegrator::Weighting::PerPixel;
    TsdfIntegrator integrator(volume, c);
    EXPECT_THROW(integrator.integrate(frame, Eigen::Isometry3d::Identity()), InvalidInputError);
    frame.weight = cv::Mat(240, 320, CV_32FC1, cv::Scalar(0.5f));
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 0.5f);
  }
}

TEST(TsdfIntegrator, OrganizedCloudsOfAnyPointTypeWithRecoveredIntrinsics) {
  const AnalyticScene scene = test::makeScene(SceneKind::Sphere);
  const PinholeCamera camera = test::smallCamera();
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const cv::Mat depth = scene.renderDepth(camera, pose, 20.0);
  Calibration calibration;
  calibration.P[0] << camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0;
  calibration.image_size = cv::Size(camera.width, camera.height);

  pcl::PointCloud<pcl::PointXYZRGB> rgb;
  depthImageToCloud(depth, calibration, 0, rgb);
  for (auto& p : rgb) {
    p.r = 200;
    p.g = 100;
    p.b = 50;
  }
  const PinholeCamera recovered = estimatePinholeCamera(rgb);
  EXPECT_NEAR(recovered.fx, camera.fx, 1e-3);
  EXPECT_NEAR(recovered.fy, camera.fy, 1e-3);
  EXPECT_NEAR(recovered.cx, camera.cx, 1e-3);
  EXPECT_NEAR(recovered.cy, camera.cy, 1e-3);

  TsdfVolume from_cloud(kVoxel, kTrunc), from_frame(kVoxel, kTrunc);
  TsdfIntegrator(from_cloud).integrate(rgb, pose); // intrinsics recovered from the cloud
  DepthFrame frame;
  frame.camera = camera;
  frame.depth = depth;
  TsdfIntegrator(from_frame).integrate(frame, pose);
  TriangleMesh a, b;
  MarchingCubes().extract(from_cloud, a);
  MarchingCubes().extract(from_frame, b);
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i)
    ASSERT_LT((a.vertices[i] - b.vertices[i]).norm(), 1e-4f);
  EXPECT_EQ(a.colors.front(), (std::array<std::uint8_t, 3>{200, 100, 50}));

  // A fusion-like type: its weight field becomes the per-pixel weight.
  pcl::PointCloud<test::PointFused> fused;
  depthImageToCloud(depth, calibration, 0, rgb);
  fused.resize(rgb.size());
  fused.width = rgb.width;
  fused.height = rgb.height;
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    fused[i].x = rgb[i].x;
    fused[i].y = rgb[i].y;
    fused[i].z = rgb[i].z;
    fused[i].rgba = 0xff000000u;
    fused[i].weight = 0.25f;
  }
  const DepthFrame f = toDepthFrame(fused, &camera);
  ASSERT_FALSE(f.weight.empty());
  EXPECT_FLOAT_EQ(f.weight.at<float>(120, 160), 0.25f);
  TsdfVolume weighted(kVoxel, kTrunc);
  TsdfIntegrator::Config c;
  c.weighting = TsdfIntegrator::Weighting::PerPixel;
  TsdfIntegrator(weighted, c).integrate(fused, pose, &camera);
  float max_weight = 0;
  for (const auto& block : weighted.blocks())
    for (const auto& v : block->voxels)
      max_weight = std::max(max_weight, v.weight);
  EXPECT_FLOAT_EQ(max_weight, 0.25f);

  // The same through a PCLPointCloud2, as the tools read files.
  pcl::PCLPointCloud2 blob;
  pcl::toPCLPointCloud2(fused, blob);
  const DepthFrame g = toDepthFrame(blob);
  EXPECT_NEAR(g.camera.fx, camera.fx, 1e-3);
  EXPECT_FLOAT_EQ(g.weight.at<float>(120, 160), 0.25f);
  EXPECT_FLOAT_EQ(g.depth.at<float>(120, 160), depth.at<float>(120, 160));
}

TEST(TsdfIntegrator, RejectsUnorganizedCloudsAndBadFrames) {
  pcl::PointCloud<pcl::PointXYZ> scan;
  for (int i = 0; i < 100; ++i)
    scan.push_back(pcl::PointXYZ(0.01f * i, 0, 2));
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume);
  try {
    integrator.integrate(scan, Eigen::Isometry3d::Identity());
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("not organized"), std::string::npos) << e.what();
  }
  DepthFrame frame;
  frame.camera = test::smallCamera();
  frame.depth = cv::Mat(10, 10, CV_32FC1, cv::Scalar(1.f));
  EXPECT_THROW(integrator.integrate(frame, Eigen::Isometry3d::Identity()), InvalidInputError);
  frame.depth = cv::Mat(240, 320, CV_16UC1, cv::Scalar(1));
  EXPECT_THROW(integrator.integrate(frame, Eigen::Isometry3d::Identity()), InvalidInputError);
  TsdfIntegrator::Config bad;
  bad.lambda = -1;
  EXPECT_THROW(integrator.setConfig(bad), ConfigError);
  // A cloud that is no pinhole projection of its pixels: intrinsics cannot be recovered.
  pcl::PointCloud<pcl::PointXYZ> noise(40, 30);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> any(-1.f, 1.f);
  for (auto& p : noise)
    p = pcl::PointXYZ(any(rng), any(rng), 2.f + any(rng));
  EXPECT_THROW(integrator.integrate(noise, Eigen::Isometry3d::Identity()), InvalidInputError);
  EXPECT_EQ(volume.numBlocks(), 0u);
}

TEST(TsdfIntegrator, UnorganizedScanFromASensorOrigin) {
  // Rays from a sensor at (0.2, -0.1, 0) onto the sphere scene, as a LiDAR would sample it.
  const AnalyticScene scene = test::makeScene(SceneKind::Sphere);
  PinholeCamera dense = test::smallCamera();
  Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();
  T_world_sensor.translation() = Eigen::Vector3d(0.2, -0.1, 0.0);
  const cv::Mat depth = scene.renderDepth(dense, T_world_sensor, 20.0);
  pcl::PointCloud<pcl::PointXYZ> points_sensor;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      if (z > 0)
        points_sensor.push_back(pcl::PointXYZ(static_cast<float>((u - dense.cx) / dense.fx * z),
                                              static_cast<float>((v - dense.cy) / dense.fy * z), z));
    }
  TsdfVolume volume(kVoxel, kTrunc);
  TsdfIntegrator integrator(volume);
  integrator.integrateScan(points_sensor, T_world_sensor);
  EXPECT_GT(integrator.lastStats().voxels_updated, 10000u);
  TriangleMesh mesh;
  MarchingCubes().extract(volume, mesh);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  const double error = test::meanVertexError(scene, mesh);
  EXPECT_LE(error, 0.1 * kVoxel) << error / kVoxel << " voxel";
}

TEST(TsdfIntegrator, SpaceCarvingRemovesASurfaceSeenThrough) {
  // First a wall at 2 m, then (it moved away) a wall at 3 m: carving empties the old one.
  for (const bool carving : {false, true}) {
    TsdfVolume volume(0.05, 0.15);
    TsdfIntegrator::Config c;
    c.space_carving = carving;
    TsdfIntegrator integrator(volume, c);
    DepthFrame frame;
    frame.camera = test::smallCamera();
    frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
    frame.depth.setTo(3.0f);
    for (int i = 0; i < 2; ++i)
      integrator.integrate(frame, Eigen::Isometry3d::Identity());
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    std::size_t near = 0, far = 0;
    for (const auto& p : mesh.vertices)
      (p.z() < 2.5f ? near : far) += 1;
    EXPECT_GT(far, 100u);
    if (carving)
      EXPECT_EQ(near, 0u);
    else
      EXPECT_GT(near, 100u);
  }
}
