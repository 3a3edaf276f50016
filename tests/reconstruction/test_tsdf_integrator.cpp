// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"
#include "test_support.h"

#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/point_types.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/mesh_rasterizer.h>
#include <msf/reconstruction/scan_free_space.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <pcl/conversions.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <utility>

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

SceneResult reconstruct(SceneKind kind, double sigma, double lambda, int frames = 5,
                        TsdfIntegrator::Config config = {}) {
  const AnalyticScene scene = test::makeScene(kind);
  TsdfVolume volume(kVoxel, kTrunc);
  config.lambda = lambda;
  TsdfIntegrator integrator(volume, config);
  const auto camera = test::smallCamera();
  const auto poses = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 15, frames);
  for (int i = 0; i < frames; ++i)
    integrator.integrate(test::renderFrame(scene, camera, poses[i], sigma, 7 + i), poses[i]);
  SceneResult r;
  // The integrator's own result: without the mesher's smoothing (tested in test_marching_cubes).
  MarchingCubes::Config unsmoothed;
  unsmoothed.smoothing_lambda = 0.f;
  MarchingCubes(unsmoothed).extract(volume, r.mesh);
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
  // Smoothed edges are where rays that pass beside the box carve: 0.979 of the box (0.98
  // without carving).
  EXPECT_GE(r.coverage, 0.975);
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

TEST(TsdfIntegrator, LambdaBeyondItsPlausibleRangeIsRefused) {
  // -lambda 1e300 flattened the surface to a 6-triangle mesh with exit code 0.
  TsdfIntegrator::Config config;
  config.lambda = TsdfIntegrator::Config::kMaxLambda;
  EXPECT_NO_THROW(config.validate());
  for (const double lambda : {1e300, 2e6, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    config.lambda = lambda;
    EXPECT_NE(test::errorOf([&] { config.validate(); }).find("tsdf_integrator.lambda (-lambda) must be 0 .. 1e6"),
              std::string::npos)
        << lambda;
  }
}

TEST(TsdfIntegrator, InverseVarianceLambdaSmoothsWhatIsUncertainAndKeepsWhatIsKnown) {
  // The same 30 mm noise on the sphere, once said to be known to 1 cm (weight 1e4 a frame,
  // LiDAR-like) and once to 0.5 m (weight 4, far-stereo-like). With the data term weighed by
  // the voxel's weight, lambda 5 leaves the first where the plain mean puts it and smooths the
  // second; the paper's uniform data term smooths both alike.
  const auto error = [](double sigma_m, double lambda, TsdfIntegrator::LambdaData data) {
    TsdfIntegrator::Config config;
    config.weighting = TsdfIntegrator::Weighting::Constant;
    config.depth_sigma_m = sigma_m;
    config.truncation_sigmas = 0.0; // the same band (kTrunc) for both
    config.lambda_data = data;
    return reconstruct(SceneKind::Sphere, 0.03, lambda, 5, config).error;
  };
  const auto by_weight = TsdfIntegrator::LambdaData::InverseVariance;
  const double known = error(0.01, 0.0, by_weight), known_smoothed = error(0.01, 5.0, by_weight);
  const double unsure = error(0.5, 0.0, by_weight), unsure_smoothed = error(0.5, 5.0, by_weight);
  std::printf("  known to 1 cm: %.2f -> %.2f mm; to 0.5 m: %.2f -> %.2f mm\n", known * 1e3, known_smoothed * 1e3,
              unsure * 1e3, unsure_smoothed * 1e3);
  EXPECT_NEAR(known_smoothed, known, 0.03 * known);
  EXPECT_LT(unsure_smoothed, 0.8 * unsure);
  const auto uniform = TsdfIntegrator::LambdaData::Uniform;
  EXPECT_LT(error(0.01, 5.0, uniform), 0.8 * known);
}

TEST(TsdfIntegrator, PlainWeightedMeanWithSignsAndWeights) {
  // Two fronto-parallel walls at 2.0 m and 2.1 m seen from the origin: with lambda = 0 a voxel
  // holds the mean of d - z, so the surface lies at 2.05 m; with depth_sigma_m 1 and no
  // drop-off behind the surface, weights count the frames.
  TsdfVolume volume(0.05, 0.3);
  TsdfIntegrator::Config config;
  config.depth_sigma_m = 1.0;
  config.truncation_sigmas = 0.0;
  config.weight_dropoff = false;
  TsdfIntegrator integrator(volume, config);
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
  MarchingCubes::Config counts;
  counts.min_weight = 0.f;
  MarchingCubes(counts).extract(volume, mesh);
  ASSERT_FALSE(mesh.vertices.empty());
  for (const auto& p : mesh.vertices)
    EXPECT_NEAR(p.z(), 2.05f, 1e-4);
}

TEST(TsdfIntegrator, WeightingModesAndMaximumWeight) {
  DepthFrame frame;
  frame.camera = test::smallCamera();
  frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
  const GridIndex at(0, 0, 40);
  // Weights are inverse variances (m^-2) of the depth.
  {
    TsdfVolume volume(0.05, 0.3);
    TsdfIntegrator::Config c;
    c.weighting = TsdfIntegrator::Weighting::Constant;
    c.depth_sigma_m = 0.1; // 100
    TsdfIntegrator(volume, c).integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 100.f);
  }
  {
    TsdfVolume volume(0.05, 0.3);
    TsdfIntegrator::Config c;
    c.weighting = TsdfIntegrator::Weighting::InverseSquare;
    c.depth_sigma_m = 0.1; // sigma 0.2 m at 2 m: 25
    TsdfIntegrator(volume, c).integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 25.f);
  }
  {
    TsdfVolume volume(0.05, 0.3);
    TsdfIntegrator::Config c;
    c.depth_sigma_m = 1.0;
    c.max_weight = 3.f;
    TsdfIntegrator integrator(volume, c);
    for (int i = 0; i < 5; ++i)
      integrator.integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 3.f);
  }
  {
    // Per pixel: the frame's weight image, or depth_sigma_m without one.
    TsdfVolume volume(0.05, 0.3);
    TsdfIntegrator::Config c;
    c.weighting = TsdfIntegrator::Weighting::PerPixel;
    c.depth_sigma_m = 0.5; // 4
    c.min_pixel_weight = 1.f;
    TsdfIntegrator integrator(volume, c);
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 4.f);
    frame.weight = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.5f));
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 6.5f);
    // Pixels below min_pixel_weight are not integrated at all.
    frame.weight.setTo(0.5f);
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
    EXPECT_FLOAT_EQ(volume.findVoxel(at)->weight, 6.5f);
    EXPECT_EQ(integrator.lastStats().voxels_updated, 0u);
  }
}

/// A weighting of one's own: sigma 0.1 m within 2.5 m, 1 m beyond.
class NearIsPrecise : public DepthWeighting {
public:
  float weight(float depth) const override { return depth < 2.5f ? 100.f : 1.f; }
  double leastWeight(double) const override { return 1.0; }
};

TEST(TsdfIntegrator, AWeightingIsATypeThatTheConfigNamesOrTheUserGives) {
  EXPECT_FLOAT_EQ(makeDepthWeighting(TsdfIntegrator::Weighting::Constant, 0.1)->weight(7.f), 100.f);
  EXPECT_FLOAT_EQ(makeDepthWeighting(TsdfIntegrator::Weighting::InverseSquare, 0.1)->weight(2.f), 25.f);
  EXPECT_DOUBLE_EQ(makeDepthWeighting(TsdfIntegrator::Weighting::InverseSquare, 0.1)->leastWeight(10.0), 1.0);
  const auto per_pixel = makeDepthWeighting(TsdfIntegrator::Weighting::PerPixel, 0.5);
  EXPECT_TRUE(per_pixel->takesFrameWeights());
  EXPECT_FLOAT_EQ(per_pixel->weight(3.f), 4.f); // without a weight image: depth_sigma_m's
  EXPECT_EQ(per_pixel->leastWeight(40.0), 0.0);

  DepthFrame frame;
  frame.camera = test::smallCamera();
  frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
  frame.depth.colRange(240, 320).setTo(3.0f);
  TsdfVolume volume(0.05, 0.3);
  TsdfIntegrator integrator(volume);
  EXPECT_TRUE(integrator.weighting().takesFrameWeights()); // the default config's per_pixel
  integrator.setWeighting(std::make_shared<NearIsPrecise>());
  EXPECT_FALSE(integrator.weighting().takesFrameWeights());
  integrator.integrate(frame, Eigen::Isometry3d::Identity());
  EXPECT_FLOAT_EQ(volume.findVoxel(GridIndex(0, 0, 40))->weight, 100.f); // on the near surface, 2 m ahead
  const double x_far = 3.0 * (280 - frame.camera.cx) / frame.camera.fx; // a pixel of the far part
  EXPECT_FLOAT_EQ(volume.findVoxel(GridIndex(static_cast<int>(std::lround(x_far / 0.05)), 0, 60))->weight, 1.f);
  EXPECT_THROW(integrator.setWeighting(nullptr), InvalidInputError);
  // A new config sets its own weighting again.
  integrator.setConfig(TsdfIntegrator::Config());
  EXPECT_TRUE(integrator.weighting().takesFrameWeights());
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

  // The fusion stage's type, through the library's own instantiation: its weight field
  // becomes the per-pixel weight.
  pcl::PointCloud<PointXYZRGBWeight> fused;
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

namespace {

/// Vertices of the old wall (z < 2.5 m) and of the new one, and of each those that keep a
/// weight (a LiDAR hold), meshed with a given component_release_passes.
struct HeldWalls {
  std::size_t old_wall = 0, old_held = 0, new_wall = 0, new_held = 0;
};
HeldWalls heldWalls(const TsdfVolume& volume, int release_passes) {
  MarchingCubes::Config whole;
  whole.min_component_triangles = 0;
  whole.component_release_passes = release_passes;
  TriangleMesh mesh;
  MarchingCubes(whole).extract(volume, mesh);
  HeldWalls h;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const bool old = mesh.vertices[i].z() < 2.5f;
    (old ? h.old_wall : h.new_wall) += 1;
    (old ? h.old_held : h.new_held) += mesh.weights[i] > 0.f;
  }
  return h;
}
/// The walls held after one more frame of the wall at 3 m, meshed by default (2), with 1 and 0.
struct Held {
  HeldWalls by_default, one, never;
};
Held passAndMesh(TsdfIntegrator& integrator, DepthFrame& frame, const TsdfVolume& volume) {
  frame.depth.setTo(3.0f);
  integrator.integrate(frame, Eigen::Isometry3d::Identity());
  return {heldWalls(volume, 2), heldWalls(volume, 1), heldWalls(volume, 0)};
}

} // namespace

TEST(TsdfIntegrator, TheFramesThatPassedASurfaceSinceItWasSeenAreCounted) {
  // A wall at 2 m seen by twenty frames, then (it moved away) at 3 m: the old wall keeps most of
  // its weight, so the mesh keeps a surface there, but the rays of each later frame pass the
  // voxels behind it. No ray had passed them before, so from the first such frame on the mesh
  // gives its vertices no weight (no LiDAR hold); the new wall's voxels are never passed.
  ASSERT_EQ(MarchingCubes::Config{}.component_release_passes, 2);
  TsdfVolume volume(0.05, 0.15);
  TsdfIntegrator::Config c;
  c.lambda = 0.0; // the plain mean
  TsdfIntegrator integrator(volume, c);
  DepthFrame frame;
  frame.camera = test::smallCamera();
  frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
  for (int i = 0; i < 20; ++i)
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
  auto voxelAt = [&](double z) { return volume.findVoxel(volume.voxelIndexOf(Eigen::Vector3d(0.0, 0.0, z))); };
  const double behind_old[] = {2.0, 2.05, 2.1}; // the voxels in front share no sub-block with a surface
  for (const double z : behind_old) {
    ASSERT_EQ(voxelAt(z)->passes(), 0) << z;
    ASSERT_FALSE(voxelAt(z)->reappeared()) << z;
  }
  const Held first_pass = passAndMesh(integrator, frame, volume);
  for (const double z : behind_old)
    EXPECT_EQ(voxelAt(z)->passes(), 1) << z;
  EXPECT_EQ(first_pass.by_default.old_held, 0u) << "no ray had passed the old wall before: one pass releases it";
  EXPECT_EQ(first_pass.never.old_held, first_pass.never.old_wall) << "0: passes release nothing";

  // The wall comes back (a leaf in the wind): the count starts again, and a surface that
  // reappeared after a pass needs component_release_passes passes in a row.
  frame.depth.setTo(2.0f);
  integrator.integrate(frame, Eigen::Isometry3d::Identity());
  for (const double z : behind_old) {
    EXPECT_EQ(voxelAt(z)->passes(), 0) << z << ": seen again";
    EXPECT_TRUE(voxelAt(z)->reappeared()) << z;
  }
  for (int passes = 1; passes <= TsdfVoxel::kMaxPasses + 1; ++passes) {
    const Held h = passAndMesh(integrator, frame, volume);
    for (const double z : behind_old) {
      EXPECT_EQ(voxelAt(z)->passes(), std::min(passes, TsdfVoxel::kMaxPasses)) << z;
      EXPECT_TRUE(voxelAt(z)->reappeared()) << z;
    }
    for (const double z : {2.95, 3.0, 3.05}) {
      EXPECT_EQ(voxelAt(z)->passes(), 0) << z;
      EXPECT_FALSE(voxelAt(z)->reappeared()) << z;
    }
    if (passes > 2)
      continue; // then the mean is carved past the surface: no old wall to mesh
    ASSERT_GT(h.by_default.old_wall, 100u);
    ASSERT_GT(h.by_default.new_wall, 100u);
    EXPECT_EQ(h.by_default.new_held, h.by_default.new_wall);
    if (passes < 2)
      EXPECT_EQ(h.by_default.old_held, h.by_default.old_wall) << passes << " frames passed";
    else
      EXPECT_EQ(h.by_default.old_held, 0u) << passes << " frames passed";
    EXPECT_EQ(h.one.old_held, 0u);
    EXPECT_EQ(h.never.old_held, h.never.old_wall) << "0: passes release nothing";
  }
}

TEST(TsdfIntegrator, FreeSpaceWeighsTheFramesFreeSpaceWeight) {
  // The wall at 2 m, then a wall at 3 m whose depth is uncertain (weight 25, sigma 0.2 m: the
  // fusion's average of two samples that disagree) but whose free space in front is not (the frame's
  // free_space_weight): the free-space weight, not the depth's, clears the old wall. A frame
  // whose free space weighs nothing keeps it.
  for (const float free : {0.f, 400.f}) {
    TsdfVolume volume(0.05, 0.15);
    TsdfIntegrator integrator(volume, TsdfIntegrator::Config{});
    DepthFrame frame;
    frame.camera = test::smallCamera();
    frame.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
    frame.weight = cv::Mat(240, 320, CV_32FC1, cv::Scalar(400.f));
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
    frame.depth.setTo(3.0f);
    frame.weight.setTo(25.f);
    frame.free_space_weight = cv::Mat(240, 320, CV_32FC1, cv::Scalar(free));
    for (int i = 0; i < 4; ++i)
      integrator.integrate(frame, Eigen::Isometry3d::Identity());
    // A voxel just behind the old wall (carving clears the sub-blocks that hold a surface):
    // -0.05 m, or towards +truncation when carved.
    const TsdfVoxel* old_wall = volume.findVoxel(volume.voxelIndexOf(Eigen::Vector3d(0.0, 0.0, 2.05)));
    ASSERT_NE(old_wall, nullptr);
    if (free > 0.f)
      EXPECT_GT(old_wall->sdf, 0.08f) << "carved: free space";
    else
      EXPECT_NEAR(old_wall->sdf, -0.05f, 0.01f) << "kept: the wall's surface";
  }
  DepthFrame bad;
  bad.camera = test::smallCamera();
  bad.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.0f));
  bad.free_space_weight = cv::Mat(10, 10, CV_32FC1, cv::Scalar(1.f));
  EXPECT_EQ(test::errorOf([&] { bad.validate(); }),
            "depth frame: the free-space weight image must be CV_32FC1 of the depth image's size");
}

namespace {

/// A street for the tests of grazing angles and free space: the road 1.65 m below camera 0
/// (KITTI's height, y down), a wall 4 m to the right along the drive, and a car-sized box in
/// the camera's lane `car_ahead_m` ahead of the camera at frame `i` (none when negative).
/// The camera drives along +z, 1 m per frame.
AnalyticScene street(int i, double car_ahead_m) {
  AnalyticScene s;
  s.addHalfSpace(Eigen::Vector3d(0, -1, 0), -1.65);
  s.addBox(Eigen::Vector3d(4.2, 0, 20), Eigen::Vector3d(0.2, 3, 30));
  if (car_ahead_m >= 0)
    s.addBox(Eigen::Vector3d(0, 1.65 - 0.75, i + car_ahead_m + 2.2), Eigen::Vector3d(0.9, 0.75, 2.2));
  return s;
}

Eigen::Isometry3d streetPose(int i) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().z() = i;
  return T;
}

/// Share of `points` within `distance` of a mesh vertex.
double coveredShare(const TriangleMesh& mesh, const std::vector<Eigen::Vector3d>& points, double distance) {
  if (mesh.vertices.empty() || points.empty())
    return 0.0;
  pcl::PointCloud<pcl::PointXYZ>::Ptr vertices(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& v : mesh.vertices)
    vertices->push_back(pcl::PointXYZ(v.x(), v.y(), v.z()));
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(vertices);
  std::vector<int> index(1);
  std::vector<float> d2(1);
  std::size_t covered = 0;
  for (const auto& p : points) {
    tree.nearestKSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), 1, index, d2);
    covered += d2[0] <= distance * distance;
  }
  return static_cast<double>(covered) / static_cast<double>(points.size());
}

/// Points of the road between `near` and `far` metres ahead of the frames' cameras.
std::vector<Eigen::Vector3d> roadSeen(const AnalyticScene& scene, const PinholeCamera& camera, int frames, double near,
                                      double far) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < frames; ++i) {
    const cv::Mat depth = scene.renderDepth(camera, streetPose(i), far);
    for (int v = 0; v < depth.rows; v += 2)
      for (int u = 0; u < depth.cols; u += 2) {
        const float z = depth.at<float>(v, u);
        const Eigen::Vector3d p = streetPose(i) * Eigen::Vector3d((u - camera.cx) / camera.fx * z,
                                                                 (v - camera.cy) / camera.fy * z, z);
        if (z >= near && std::abs(p.y() - 1.65) < 1e-3)
          points.push_back(p);
      }
  }
  return points;
}

/// The LiDAR's frame (x forward, y left, z up) at a camera-like pose of the street (x right,
/// y down, z forward) at `position`.
Eigen::Isometry3d lidarPose(const Eigen::Vector3d& position) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = Eigen::Vector3d::UnitZ();
  T.linear().col(1) = -Eigen::Vector3d::UnitX();
  T.linear().col(2) = -Eigen::Vector3d::UnitY();
  T.translation() = position;
  return T;
}

/// A 64-ring scan of `scene` (HDL-64's elevations, -24.8 to +2 degrees; 0.2 degrees of
/// azimuth) from T_world_lidar, by sphere tracing, in the LiDAR's frame; rays that hit nothing
/// within 80 m give no return.
pcl::PointCloud<pcl::PointXYZI> ringScan(const AnalyticScene& scene, const Eigen::Isometry3d& T_world_lidar) {
  pcl::PointCloud<pcl::PointXYZI> scan;
  for (int ring = 0; ring < 64; ++ring) {
    const double elevation = (-24.8 + 26.8 * ring / 63.0) * M_PI / 180.0;
    for (double azimuth = -180.0; azimuth < 180.0; azimuth += 0.2) {
      const double a = azimuth * M_PI / 180.0;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(a), std::cos(elevation) * std::sin(a), std::sin(elevation));
      const Eigen::Vector3d d_world = T_world_lidar.linear() * d;
      double t = 0.05;
      for (int step = 0; step < 400 && t < 80.0; ++step) {
        const double s = scene.signedDistance(T_world_lidar.translation() + t * d_world);
        if (s < 1e-4) {
          pcl::PointXYZI p;
          p.getVector3fMap() = (t * d).cast<float>();
          p.intensity = 0.f;
          scan.push_back(p);
          break;
        }
        t += s;
      }
    }
  }
  return scan;
}

} // namespace

TEST(TsdfIntegrator, GrazingGroundIsMeshedWithThePlaneDistance) {
  // 10-20 m ahead the ray meets the road at 5-9 degrees: a band of +-truncation along the ray
  // is 3-5 cm high, so the projective distance leaves most of the road without a sign change
  // between two observed voxels; the distance to the road's plane keeps one voxel each side.
  const AnalyticScene scene = street(0, -1);
  const PinholeCamera camera = test::kittiCamera();
  double covered[2];
  for (int plane = 0; plane < 2; ++plane) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator::Config c;
    c.signed_distance = plane ? TsdfIntegrator::SignedDistance::Plane : TsdfIntegrator::SignedDistance::Projective;
    TsdfIntegrator integrator(volume, c);
    for (int i = 0; i < 3; ++i)
      integrator.integrate(test::renderFrame(scene, camera, streetPose(i), 0.0), streetPose(i));
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    covered[plane] = coveredShare(mesh, roadSeen(scene, camera, 3, 10.0, 19.5), 0.1); // renderFrame stops at 20 m
    if (plane) {
      // Vertices between two observed voxels lie within 3 cm of the road; those next to a voxel no
      // frame reached (weight 0: MarchingCubes::Config::max_unseen_corners, here at the side of the
      // view 20 m ahead, where the unseen corner may lie above the road) within half a voxel.
      double worst = 0, worst_unseen = 0;
      std::size_t unseen = 0;
      ASSERT_EQ(mesh.weights.size(), mesh.vertices.size());
      for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
        const auto& v = mesh.vertices[k];
        if (!(v.x() < 3.5)) // the road, not the wall
          continue;
        const double off = std::abs(v.y() - 1.65);
        (mesh.weights[k] > 0.f ? worst : worst_unseen) = std::max(mesh.weights[k] > 0.f ? worst : worst_unseen, off);
        unseen += mesh.weights[k] > 0.f ? 0 : 1;
      }
      EXPECT_LT(worst, 0.03);
      EXPECT_LE(worst_unseen, 0.05 + 1e-4);
      std::printf("  road vertices next to an unseen voxel: %zu, worst %.3f m\n", unseen, worst_unseen);
    }
  }
  std::printf("  road 10-20 m within 0.1 m of the mesh: projective %.3f, plane %.3f\n", covered[0], covered[1]);
  EXPECT_GE(covered[1], 0.98);
  EXPECT_LT(covered[0], 0.5);
}

TEST(TsdfIntegrator, AStreetAtAnAngleToTheGridIsMeshedWithoutHoles) {
  // A street at an angle to the volume's grid, its road cambered: the corners of a cube that a
  // plane of normal n crosses lie up to (|n_x| + |n_y| + |n_z|) voxels from it, more than one.
  // A band of one voxel behind the plane left the farther ones unobserved, and marching cubes,
  // which needs all 8, left holes: 3.4 % of the pixels (0.6 % with a voxel and a half, the
  // rest along the wall's top edge and its foot).
  const double yaw = 40.0 * M_PI / 180.0, camber = 3.0 * M_PI / 180.0;
  const Eigen::Isometry3d turn(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d up = turn.linear() * Eigen::Vector3d(std::sin(camber), -std::cos(camber), 0.0);
  AnalyticScene scene;
  scene.addHalfSpace(up, up.dot(Eigen::Vector3d(0, 1.65, 0)));
  scene.addBox(turn * Eigen::Vector3d(4.2, 0, 20), Eigen::Vector3d(0.2, 3, 30), turn.linear());
  const PinholeCamera camera = test::kittiCamera();
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume, TsdfIntegrator::Config{});
  const int frames = 3;
  for (int i = 0; i < frames; ++i)
    integrator.integrate(test::renderFrame(scene, camera, turn * streetPose(i)), turn * streetPose(i));
  TriangleMesh mesh;
  MarchingCubes().extract(volume, mesh);
  MeshRasterizer rasterizer;
  std::size_t seen = 0, missed = 0;
  for (int i = 0; i < frames; ++i) {
    const cv::Mat truth = scene.renderDepth(camera, turn * streetPose(i), 20.0);
    cv::Mat rendered;
    rasterizer.render(mesh, camera, turn * streetPose(i), rendered);
    for (int v = 0; v < truth.rows - 20; ++v) // the map ends a voxel inside the view
      for (int u = 20; u < truth.cols - 20; ++u)
        if (truth.at<float>(v, u) >= 5.f && truth.at<float>(v, u) <= 18.f) {
          ++seen;
          missed += !(rendered.at<float>(v, u) > 0.f);
        }
  }
  const double missing = static_cast<double>(missed) / static_cast<double>(seen);
  std::printf("  street at 40 degrees to the grid, road cambered 3 degrees, 5-18 m: %.4f of the pixels without a surface\n", missing);
  EXPECT_LT(missing, 0.01);
}

TEST(TsdfIntegrator, CarvingRemovesTheGhostOfACarAheadAndKeepsTheStreet) {
  // A car drives ahead at the camera's speed (the KITTI van): each frame sees its rear 8 m
  // ahead. The next frames look through where it was, onto its new place: free space clears
  // the old rears, while the road and the wall, seen by every frame, stay.
  const PinholeCamera camera = test::kittiCamera();
  const int frames = 8;
  std::size_t ghosts[2] = {0, 0};
  for (const bool carving : {false, true}) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator::Config c;
    c.space_carving = carving;
    TsdfIntegrator integrator(volume, c);
    for (int i = 0; i < frames; ++i)
      integrator.integrate(test::renderFrame(street(i, 8.0), camera, streetPose(i), 0.0), streetPose(i));
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    // Vertices in the car's lane above the road, where its rear was at frames 0..frames-2.
    for (const auto& v : mesh.vertices)
      ghosts[carving] += std::abs(v.x()) < 0.8f && v.y() < 1.5f && v.z() > 7.5f && v.z() < frames - 1 + 8.f - 0.2f;
    const AnalyticScene static_street = street(0, -1);
    const double road = coveredShare(mesh, roadSeen(static_street, camera, frames, 7.0, 7.9), 0.1);
    std::vector<Eigen::Vector3d> wall;
    for (double z = 6; z < 20; z += 0.5)
      for (double y = 0; y < 1.5; y += 0.25)
        wall.push_back(Eigen::Vector3d(4.0, y, z));
    const double wall_covered = coveredShare(mesh, wall, 0.1);
    std::printf("  carving %d: %zu ghost vertices, road %.3f, wall %.3f\n", carving, ghosts[carving], road,
                wall_covered);
    EXPECT_GE(road, 0.98);
    EXPECT_GE(wall_covered, 0.98);
  }
  // What remains is the rear of the last frames, seen through once or twice.
  EXPECT_GT(ghosts[0], 1000u);
  EXPECT_LT(ghosts[1], ghosts[0] / 20);
}

TEST(TsdfIntegrator, AStoppedCarsPlaceLosesTheLidarsHoldOnceItLeftAndABollardKeepsIt) {
  // A car's back (a board) stands 12 m on while the camera drives towards it, then drives off;
  // a bollard stands beside the lane, and a wall 25 m on ends every ray. Six frames of precise
  // hits outweigh the few frames that then look through the car's place: its surface stays in
  // the map, a small piece the LiDAR's weight holds. No ray reached the car's inside before, so
  // once rays passed it, it loses that hold; the bollard, a small piece too but hit by every
  // frame, keeps it.
  const PinholeCamera camera = test::kittiCamera();
  const Eigen::Vector3d board(0.0, 0.6, 12.0), board_half(0.9, 0.6, 0.1);
  const Eigen::Vector3d bollard(-2.0, 1.15, 14.0), bollard_half(0.1, 0.5, 0.1);
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume, TsdfIntegrator::Config{});
  auto near = [](const Eigen::Vector3f& v, const Eigen::Vector3d& centre, const Eigen::Vector3d& half) {
    return ((v.cast<double>() - centre).cwiseAbs() - half).maxCoeff() < 0.15;
  };
  // Vertices of the car's place and of the bollard, meshed with component_release_passes 0, 2.
  auto meshed = [&](int release_passes) {
    MarchingCubes::Config c;
    c.component_release_passes = release_passes;
    TriangleMesh mesh;
    MarchingCubes(c).extract(volume, mesh);
    std::array<std::size_t, 2> n = {0, 0};
    for (const auto& v : mesh.vertices) {
      n[0] += near(v, board, board_half);
      n[1] += near(v, bollard, bollard_half);
    }
    return n;
  };
  for (int i = 0; i < 8; ++i) {
    AnalyticScene scene;
    scene.addHalfSpace(Eigen::Vector3d(0, 0, -1), -25.0);
    scene.addBox(bollard, bollard_half);
    if (i < 6)
      scene.addBox(board, board_half);
    integrator.integrate(test::renderFrame(scene, camera, streetPose(i), 0.0), streetPose(i));
    if (i == 6) { // passed once: no ray had passed the car's inside before
      const auto once = meshed(2);
      EXPECT_EQ(once[0], 0u) << "one frame's pass releases the car's place";
      EXPECT_GT(once[1], 50u) << "the bollard";
    }
  }
  const auto held = meshed(0), released = meshed(2);
  EXPECT_GT(held[0], 50u) << "the car's place, held by its weight";
  EXPECT_EQ(released[0], 0u);
  EXPECT_GT(held[1], 50u);
  EXPECT_EQ(released[1], held[1]) << "the bollard";
}

TEST(TsdfIntegrator, ARoofSeenAtAGrazingAngleIsMeshedWithoutASkirt) {
  // A box 1.2 m tall 8-12 m ahead, its roof 0.45 m below the camera: seen at 2-3 degrees, the
  // roof's plane runs metres along the rays, but behind its far edge is free space (then the
  // road 1.2 m lower): the band below the plane stops where the roof is seen to stop.
  AnalyticScene scene;
  scene.addHalfSpace(Eigen::Vector3d(0, -1, 0), -1.65);
  scene.addBox(Eigen::Vector3d(0, 1.65 - 0.6, 10), Eigen::Vector3d(0.9, 0.6, 2));
  const PinholeCamera camera = test::kittiCamera();
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume);
  for (int i = 0; i < 3; ++i) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(0.3 * i, 0, 0); // a little sideways: the box stays ahead
    DepthFrame frame;
    frame.camera = camera;
    frame.depth = scene.renderDepth(camera, pose, 60.0); // the road past the box too: free space over it
    integrator.integrate(frame, pose);
  }
  TriangleMesh mesh;
  MarchingCubes().extract(volume, mesh);
  std::size_t roof = 0, skirt = 0;
  for (const auto& v : mesh.vertices) {
    const bool over_box = std::abs(v.x()) < 0.8f;
    roof += over_box && std::abs(v.y() - 0.45f) < 0.05f && v.z() > 8.2f && v.z() < 11.8f;
    skirt += over_box && v.y() < 1.5f && v.z() > 12.3f && v.z() < 19.f; // above the road behind the box
  }
  std::printf("  roof vertices %zu, skirt vertices %zu\n", roof, skirt);
  EXPECT_GT(roof, 100u);
  EXPECT_EQ(skirt, 0u);
}

TEST(TsdfIntegrator, APoleSeenByFarStereoLeavesNoSheetInItsShadow) {
  // A pole 0.2 m wide 12 m ahead of a wall at 30 m, seen while driving towards it, every pixel
  // with far stereo's sigma of 1 m: the band behind a pixel is 2 m. Every frame sees the 2 m
  // behind the pole through the pole, and the wall past its sides: that band meets free space
  // along the rays past its silhouette, and marching cubes meshed the meeting as two sheets
  // reaching 2 m behind a pole 0.2 m thick. With silhouette_band the band behind the pole's
  // pixels is its width, at least two truncations.
  AnalyticScene scene;
  scene.addHalfSpace(Eigen::Vector3d(0, 0, -1), -30.0);
  scene.addBox(Eigen::Vector3d(1.0, 0, 12), Eigen::Vector3d(0.1, 20, 0.1));
  const PinholeCamera camera = test::smallCamera();
  const auto sheet_and_pole = [&](bool silhouette_band) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator::Config config;
    config.silhouette_band = silhouette_band;
    TsdfIntegrator integrator(volume, config);
    for (int i = 0; i < 8; ++i) {
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = Eigen::Vector3d(0, 0, 0.5 * i);
      DepthFrame frame;
      frame.camera = camera;
      frame.depth = scene.renderDepth(camera, pose, 40.0);
      frame.weight = cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(1.f)); // sigma 1 m
      integrator.integrate(frame, pose);
    }
    TriangleMesh mesh;
    MarchingCubes::Config every_piece; // the pole is a small piece of low weight
    every_piece.min_component_triangles = 0;
    MarchingCubes(every_piece).extract(volume, mesh);
    std::size_t sheet = 0, front = 0;
    for (const auto& v : mesh.vertices) {
      const bool beside = std::abs(v.x() - 1.f) < 0.5f && std::abs(v.y()) < 1.f;
      front += beside && std::abs(v.z() - 11.9f) < 0.1f && std::abs(v.x() - 1.f) < 0.1f;
      sheet += beside && v.z() > 12.1f + 0.6f + 0.2f && v.z() < 28.f; // past the floor of two truncations
    }
    std::printf("  silhouette_band %d: pole front vertices %zu, sheet vertices %zu\n", silhouette_band, front, sheet);
    return std::make_pair(sheet, front);
  };
  const auto [sheet_before, front_before] = sheet_and_pole(false);
  const auto [sheet, front] = sheet_and_pole(true);
  EXPECT_GT(sheet_before, 20u); // the sheets the option removes
  EXPECT_EQ(sheet, 0u);
  EXPECT_GT(front, 10u); // and the pole stays
  EXPECT_GE(front + 5, front_before);
}

TEST(TsdfIntegrator, FarStereoNeitherOverwritesNearLidarGeometryNorLeavesSpecks) {
  // Weights are inverse variances: a LiDAR-backed wall at 5 m (sigma 3 cm: 1111 m^-2), then
  // frames of far stereo through it (20 m, sigma 1 m: 1 m^-2, say a mismatch in the sky). The
  // free space those rays claim weighs a thousandth of the wall: the wall stays. Nor is the far
  // match a surface of its own: four frames of it weigh 4 m^-2, not above marching cubes' 4.
  const PinholeCamera camera = test::smallCamera();
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume);
  DepthFrame frame;
  frame.camera = camera;
  frame.depth = cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(5.f));
  frame.weight = cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(1111.f));
  integrator.integrate(frame, Eigen::Isometry3d::Identity());
  frame.depth.setTo(20.f);
  frame.weight.setTo(1.f);
  ASSERT_EQ(MarchingCubes::Config().min_weight, 4.f);
  for (int i = 0; i < 4; ++i)
    integrator.integrate(frame, Eigen::Isometry3d::Identity());
  TriangleMesh mesh;
  MarchingCubes().extract(volume, mesh);
  std::size_t wall = 0, far = 0;
  for (const auto& v : mesh.vertices)
    (std::abs(v.z() - 5.f) < 0.05f ? wall : far) += 1;
  EXPECT_GT(wall, 1500u); // 5.3 m x 4 m at 0.1 m
  EXPECT_EQ(far, 0u);
  // Seen 11 times (11 m^-2), the same far surface is meshed: the minimum is a precision.
  TsdfVolume far_only(0.1, 0.3);
  TsdfIntegrator far_integrator(far_only);
  for (int i = 0; i < 11; ++i)
    far_integrator.integrate(frame, Eigen::Isometry3d::Identity());
  MarchingCubes().extract(far_only, mesh);
  EXPECT_GT(mesh.vertices.size(), 1000u);
}

TEST(TsdfIntegrator, PreciseDepthIsIntegratedBeyondMaxDepthAndTheRestIsNot) {
  // Two walls beyond max_depth_m (40 m), left and right halves of the image at 50 m: one known
  // to 3 cm (a LiDAR return: 1111 m^-2), one to 0.5 m (far stereo: 4 m^-2, three frames
  // above marching cubes' minimum). precise_max_depth_m (60 m) keeps the first and drops the
  // second; 0 drops both; a pixel known to within the truncation (0.3 m: >= 11.1 m^-2) counts.
  const PinholeCamera camera = test::smallCamera();
  auto wallVertices = [&](TsdfIntegrator::Config config, float right_weight, bool weighted = true) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator integrator(volume, config);
    DepthFrame frame;
    frame.camera = camera;
    frame.depth = cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(50.f));
    frame.weight = cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(1111.f));
    frame.weight.colRange(camera.width / 2, camera.width).setTo(right_weight);
    if (!weighted)
      frame.weight.release();
    for (int i = 0; i < 3; ++i)
      integrator.integrate(frame, Eigen::Isometry3d::Identity());
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    std::array<std::size_t, 2> sides{0, 0}; // left, right of the optical axis (a voxel's margin)
    for (const auto& v : mesh.vertices) {
      EXPECT_NEAR(v.z(), 50.f, 0.05f);
      if (std::abs(v.x()) > 0.5f)
        sides[v.x() > 0.f] += 1;
    }
    return sides;
  };
  TsdfIntegrator::Config config;
  ASSERT_EQ(config.max_depth_m, 40.0);
  ASSERT_EQ(config.precise_max_depth_m, 60.0);
  const auto shipped = wallVertices(config, 4.f);
  EXPECT_GT(shipped[0], 2000u); // the left half of the wall seen at 50 m, 26 m x 40 m
  EXPECT_EQ(shipped[1], 0u);
  const auto within_truncation = wallVertices(config, 11.2f);
  EXPECT_GT(within_truncation[1], 2000u);
  // Depth without weights of its own (depth_sigma_m, 5 cm) is cut at max_depth_m.
  const auto unweighted = wallVertices(config, 1111.f, false);
  EXPECT_EQ(unweighted[0] + unweighted[1], 0u);
  config.precise_max_depth_m = 45.0; // nearer than the wall
  EXPECT_EQ(wallVertices(config, 1111.f)[0], 0u);
  config.precise_max_depth_m = 0.0;
  EXPECT_EQ(wallVertices(config, 1111.f)[0], 0u);
  // Its reach covers the precise depth.
  TsdfVolume volume(0.1, 0.3);
  config.precise_max_depth_m = 60.0;
  EXPECT_GT(TsdfIntegrator(volume, config).allocationDepth(), 60.0);
  for (const double bad : {-1.0, 2000.0, std::nan("")}) {
    config.precise_max_depth_m = bad;
    try {
      config.validate();
      ADD_FAILURE() << "accepted precise_max_depth_m " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("tsdf_integrator.precise_max_depth_m"), std::string::npos) << e.what();
    }
  }
}

namespace {

/// The volume after one noisy frame of the sphere scene with lambda 5, solved as `config` says.
TsdfVolume regularizedOnce(TsdfIntegrator::Config config, TsdfIntegrator::Stats* stats = nullptr) {
  const AnalyticScene scene = test::makeScene(SceneKind::Sphere);
  TsdfVolume volume(kVoxel, kTrunc);
  config.lambda = 5.0;
  config.weighting = TsdfIntegrator::Weighting::Constant;
  TsdfIntegrator integrator(volume, config);
  const auto pose = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 15, 1).front();
  integrator.integrate(test::renderFrame(scene, test::smallCamera(), pose, 0.02, 11), pose);
  if (stats)
    *stats = integrator.lastStats();
  return volume;
}

/// The largest |sdf| difference of the voxels observed in both volumes.
double largestDifference(const TsdfVolume& a, const TsdfVolume& b) {
  double largest = 0;
  for (const TsdfBlock* block : a.blocks()) {
    const TsdfBlock* other = b.findBlock(block->index);
    if (!other)
      continue;
    for (int j = 0; j < TsdfBlock::kVoxels; ++j)
      if (block->voxels[j].weight > 0.f && other->voxels[j].weight > 0.f)
        largest = std::max(largest, static_cast<double>(std::abs(block->voxels[j].sdf - other->voxels[j].sdf)));
  }
  return largest;
}

} // namespace

TEST(TsdfIntegrator, ArgminSolveReachesTheMinimizerOfEquation7) {
  // The minimizer does not depend on how it is reached: sweeping until nothing moves more than
  // the tolerance lands where the most sweeps allowed land, and far from one sweep.
  TsdfIntegrator::Config argmin;
  argmin.solve = TsdfIntegrator::Solve::Argmin;
  argmin.argmin_tolerance_m = 1e-6;
  TsdfIntegrator::Stats stats;
  const TsdfVolume solved = regularizedOnce(argmin, &stats);
  EXPECT_TRUE(stats.regularize_converged);
  EXPECT_GT(stats.regularize_sweeps, 10);
  EXPECT_LT(stats.regularize_sweeps, argmin.argmin_max_sweeps);
  TsdfIntegrator::Config many, one;
  many.sweeps = TsdfIntegrator::Config::kMaxSweeps;
  one.sweeps = 1;
  const double to_many = largestDifference(solved, regularizedOnce(many));
  const double to_one = largestDifference(solved, regularizedOnce(one));
  std::printf("  argmin in %d sweeps: %.2g m from 100 sweeps, %.2g m from one\n", stats.regularize_sweeps, to_many,
              to_one);
  EXPECT_LT(to_many, 1e-4);
  EXPECT_GT(to_one, 10 * to_many);
  // A cap on the sweeps is reported as not converged.
  argmin.argmin_max_sweeps = 2;
  regularizedOnce(argmin, &stats);
  EXPECT_FALSE(stats.regularize_converged);
  EXPECT_EQ(stats.regularize_sweeps, 2);
}

/// A schedule of one's own: three sweeps, reported as converged once a sweep moved less than 1 m.
class ThreeSweeps : public SweepSchedule {
public:
  int maxSweeps() const override { return 3; }
  bool converged(float largest_change) const override { return largest_change < 1.f; }
  bool runsEverySweep() const override { return false; }
};

TEST(TsdfIntegrator, TheSolveIsASweepScheduleThatTheConfigNamesOrTheUserGives) {
  TsdfIntegrator::Config config;
  config.solve = TsdfIntegrator::Solve::Argmin;
  config.argmin_tolerance_m = 1e-3;
  config.argmin_max_sweeps = 50;
  const auto argmin = makeSweepSchedule(config);
  EXPECT_EQ(argmin->maxSweeps(), 50);
  EXPECT_TRUE(argmin->converged(1e-3f));
  EXPECT_FALSE(argmin->converged(2e-3f));
  config.solve = TsdfIntegrator::Solve::Sweeps;
  config.sweeps = 4;
  const auto sweeps = makeSweepSchedule(config);
  EXPECT_EQ(sweeps->maxSweeps(), 4);
  EXPECT_TRUE(sweeps->runsEverySweep());
  EXPECT_FALSE(sweeps->converged(0.f)); // a fixed count: never stops early

  // The schedule given decides: the first sweep moves less than a metre, so one sweep runs,
  // and the volume is the one a single fixed sweep gives.
  TsdfVolume volume(kVoxel, kTrunc);
  TsdfIntegrator::Config one;
  one.lambda = 5.0;
  one.weighting = TsdfIntegrator::Weighting::Constant;
  TsdfIntegrator integrator(volume, one);
  integrator.setSweepSchedule(std::make_shared<ThreeSweeps>());
  const AnalyticScene scene = test::makeScene(SceneKind::Sphere);
  const auto pose = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 15, 1).front();
  integrator.integrate(test::renderFrame(scene, test::smallCamera(), pose, 0.02, 11), pose);
  EXPECT_EQ(integrator.lastStats().regularize_sweeps, 1);
  EXPECT_TRUE(integrator.lastStats().regularize_converged);
  EXPECT_EQ(largestDifference(volume, regularizedOnce(TsdfIntegrator::Config())), 0.0);
  EXPECT_THROW(integrator.setSweepSchedule(nullptr), InvalidInputError);
  integrator.setConfig(one); // a new config sets its own schedule again
  EXPECT_EQ(integrator.sweepSchedule().maxSweeps(), 1);
}

TEST(TsdfIntegrator, TheSignedDistanceIsAModelThatTheConfigNamesOrTheUserGives) {
  // A ground plane seen at a grazing angle: the plane distance shrinks the scale below 1, the
  // projective distance keeps 1 and sees no surface behind the pixel.
  const PinholeCamera camera = test::smallCamera();
  AnalyticScene scene;
  scene.addHalfSpace(Eigen::Vector3d(0, -1, 0), -1.5); // a floor 1.5 m below the camera (y down)
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const cv::Mat depth = scene.renderDepth(camera, pose, 20.0);
  cv::Mat scale, extent;
  makeSignedDistance(TsdfIntegrator::SignedDistance::Projective, {})->pixelScales(depth, camera, scale, extent);
  EXPECT_EQ(cv::norm(scale - 1.f, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(extent), 0);
  const PlaneDistanceConfig plane;
  makeSignedDistance(TsdfIntegrator::SignedDistance::Plane, plane)->pixelScales(depth, camera, scale, extent);
  cv::Mat expected;
  planeDistanceScale(depth, camera, plane, expected);
  EXPECT_EQ(cv::norm(scale, expected, cv::NORM_INF), 0.0);
  const int v = camera.height - 10, u = camera.width / 2; // the road a few metres ahead
  ASSERT_GT(depth.at<float>(v, u), 0.f);
  EXPECT_LT(scale.at<float>(v, u), 0.5f);
  EXPECT_GT(extent.at<float>(v, u), depth.at<float>(v, u));

  // Given to the integrator, the model decides, as the config's word would.
  const DepthFrame frame = test::renderFrame(scene, camera, pose, 0.0, 1);
  TsdfVolume by_word(kVoxel, kTrunc), by_model(kVoxel, kTrunc);
  TsdfIntegrator::Config projective;
  projective.signed_distance = TsdfIntegrator::SignedDistance::Projective;
  TsdfIntegrator(by_word, projective).integrate(frame, pose);
  TsdfIntegrator integrator(by_model); // the default config's plane distance
  integrator.setSignedDistance(std::make_shared<ProjectiveDistance>());
  integrator.integrate(frame, pose);
  ASSERT_EQ(by_word.numObservedVoxels(), by_model.numObservedVoxels());
  EXPECT_EQ(largestDifference(by_word, by_model), 0.0);
  EXPECT_THROW(integrator.setSignedDistance(nullptr), InvalidInputError);
}

TEST(TsdfIntegrator, SolveKeysAreNamedWhenWrong) {
  for (const std::string key :
       {"solve: exact", "argmin_tolerance_m: 0", "argmin_max_sweeps: 0", "lambda_data: weighted"}) {
    TsdfIntegrator::Config config;
    try {
      ConfigFile::fromText("tsdf_integrator:\n  " + key + "\n", "c.yaml").read(config);
      ADD_FAILURE() << key << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("tsdf_integrator." + key.substr(0, key.find(':'))), std::string::npos)
          << e.what();
    }
  }
}

TEST(ScanFreeSpace, TheNearestReturnAroundADirection) {
  // Returns on a sphere 10 m around the sensor, one nearer return at 6 m straight ahead.
  pcl::PointCloud<pcl::PointXYZI> scan;
  for (double el = -20; el <= 10; el += 0.25)
    for (double az = -180; az < 180; az += 0.2) {
      const double e = el * M_PI / 180, a = az * M_PI / 180;
      pcl::PointXYZI p;
      p.x = static_cast<float>(10 * std::cos(e) * std::cos(a));
      p.y = static_cast<float>(10 * std::cos(e) * std::sin(a));
      p.z = static_cast<float>(10 * std::sin(e));
      scan.push_back(p);
    }
  pcl::PointXYZI near;
  near.x = 6.f;
  near.y = near.z = 0.f;
  scan.push_back(near);
  pcl::PointXYZI bad;
  bad.x = bad.y = bad.z = std::nanf("");
  scan.push_back(bad);
  const ScanFreeSpace free_space(scan);
  ASSERT_FALSE(free_space.empty());
  EXPECT_NEAR(free_space.nearestAround(Eigen::Vector3f(0, 5, 0.5f)), 10.f, 1e-3f);
  EXPECT_NEAR(free_space.nearestAround(Eigen::Vector3f(-3, -2, -1)), 10.f, 1e-3f);
  // The near return lowers its bin and the 8 around it, not farther ones.
  EXPECT_NEAR(free_space.nearestAround(Eigen::Vector3f(3, 0, 0)), 6.f, 1e-3f);
  const float beside = std::tan(0.5f * static_cast<float>(M_PI) / 180.f); // 0.5 degrees: the next bin
  EXPECT_NEAR(free_space.nearestAround(Eigen::Vector3f(1, beside, 0)), 6.f, 1e-3f);
  EXPECT_NEAR(free_space.nearestAround(Eigen::Vector3f(1, 4 * beside, 0)), 10.f, 1e-3f);
  // Above every return (no return in the bin) and beyond the elevations kept: nothing known.
  EXPECT_EQ(free_space.nearestAround(Eigen::Vector3f(1, 0, 0.5f)), 0.f);
  EXPECT_EQ(free_space.nearestAround(Eigen::Vector3f(0, 0, 1)), 0.f);
  EXPECT_TRUE(ScanFreeSpace().empty());
  EXPECT_EQ(ScanFreeSpace().nearestAround(Eigen::Vector3f(1, 0, 0)), 0.f);
}

TEST(ScanFreeSpace, AReturnUnderTheGroundClearsNothing) {
  // A level road 1.73 m under the sensor, rings from -24 to -8 degrees. Ahead and to the right a
  // wet patch mirrors the two lowest rings on to a van 20.7 m on and sends the rings above them
  // nowhere (as on KITTI odometry 04, frames 10-16): the mirrored returns lie 6.6 m under the
  // road, and taken whole they would clear the road from underneath. Their beams end at the
  // road. A kerb 0.5 m under the road to the left (a ditch's edge) is taken whole.
  constexpr double kHeight = 1.73;
  const auto at = [](double range, double el_deg, double az_deg) {
    const double e = el_deg * M_PI / 180, a = az_deg * M_PI / 180;
    pcl::PointXYZI p;
    p.x = static_cast<float>(range * std::cos(e) * std::cos(a));
    p.y = static_cast<float>(range * std::cos(e) * std::sin(a));
    p.z = static_cast<float>(range * std::sin(e));
    return p;
  };
  const auto mirrored = [](double el_deg, double az_deg) { return el_deg < -23.4 && std::abs(az_deg + 15) < 1; };
  const auto ditch = [](double az_deg) { return std::abs(az_deg - 90) < 2; };
  pcl::PointCloud<pcl::PointXYZI> scan;
  std::size_t mirrored_returns = 0, ditch_returns = 0;
  for (double el = -24.15; el <= -8; el += 0.5)
    for (double az = -180; az < 180; az += 0.2) {
      const double down = std::sin(-el * M_PI / 180);
      if (mirrored(el, az)) {
        scan.push_back(at(20.7, el, az));
        ++mirrored_returns;
      } else if (std::abs(az + 15) < 1 && el < -17) {
        continue; // the beams the patch sent away
      } else if (ditch(az) && el < -14) {
        scan.push_back(at((kHeight + 0.5) / down, el, az));
        ++ditch_returns;
      } else {
        scan.push_back(at(kHeight / down, el, az));
      }
    }
  ASSERT_GT(ditch_returns, 0u);
  const ScanFreeSpace free_space(scan);
  EXPECT_EQ(free_space.belowGround(), mirrored_returns);
  // Where the mirrored beams point, free space ends at the road, 4.2-4.3 m on: not under it.
  const float to_road = static_cast<float>(kHeight / std::sin(24.15 * M_PI / 180));
  const pcl::PointXYZI under_road = at(to_road + 0.2, -23.9, -15);
  EXPECT_NEAR(free_space.nearestAround(under_road.getVector3fMap()), to_road, 0.01f);
  // A road falling away far off frees its beams as far as they meet the plane: a return 1.5 m
  // under the road 50 m on frees its beam to 26.8 m, beyond the carving's reach (20 m and a metre).
  pcl::PointCloud<pcl::PointXYZI> falling = scan;
  const pcl::PointXYZI far_road = at(50, -std::asin((kHeight + 1.5) / 50) * 180 / M_PI, 45);
  falling.push_back(far_road);
  const pcl::PointXYZI on_the_way = at(20, -std::asin((kHeight + 1.5) / 50) * 180 / M_PI, 45);
  EXPECT_NEAR(ScanFreeSpace(falling).nearestAround(on_the_way.getVector3fMap()), 50 * kHeight / (kHeight + 1.5), 0.01);
  // The kerb's returns are kept: its bins hold them.
  const pcl::PointXYZI kerb = at(4.0, -20.15, 90);
  EXPECT_NEAR(free_space.nearestAround(kerb.getVector3fMap()), (kHeight + 0.5) / std::sin(20.65 * M_PI / 180), 0.05);

  // Nothing lies under a scan without ground in sight (a sphere's lower half is no plane).
  pcl::PointCloud<pcl::PointXYZI> sphere;
  for (double el = -20; el <= 10; el += 0.25)
    for (double az = -180; az < 180; az += 0.2)
      sphere.push_back(at(10, el, az));
  EXPECT_EQ(ScanFreeSpace(sphere).belowGround(), 0u);
}

TEST(TsdfIntegrator, ScanCarvingClearsWhatDroveAwayOutOfViewAndKeepsTheStreet) {
  // An oncoming car 8 m ahead in the other lane at frame 0; it has passed by frame 1, when the
  // camera is 12 m on and never sees its place again. The camera's own free space cannot clear
  // it; the LiDAR's scans, all around, see the road behind through it.
  const PinholeCamera camera = test::kittiCamera();
  AnalyticScene with_car = street(0, -1);
  with_car.addBox(Eigen::Vector3d(-2.5, 1.65 - 0.75, 8.0), Eigen::Vector3d(0.9, 0.75, 2.2));
  const AnalyticScene static_street = street(0, -1);
  std::size_t ghosts[2] = {0, 0};
  double road[2] = {0, 0}, wall[2] = {0, 0};
  for (const bool scan_carving : {false, true}) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator::Config c;
    c.scan_carving_m = scan_carving ? 20.0 : 0.0;
    TsdfIntegrator integrator(volume, c);
    for (const int z : {0, 12, 16}) {
      const AnalyticScene& scene = z == 0 ? with_car : static_street;
      const DepthFrame frame = test::renderFrame(scene, camera, streetPose(z), 0.0);
      integrator.integrate(frame, streetPose(z));
      const Eigen::Isometry3d T_world_lidar = lidarPose(Eigen::Vector3d(0, 0, z));
      integrator.carveWithScan(ScanFreeSpace(ringScan(scene, T_world_lidar)), T_world_lidar, 1111.f, frame.camera,
                               streetPose(z));
    }
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    // The car's sides and top, half a metre and more above the road.
    for (const auto& v : mesh.vertices)
      ghosts[scan_carving] += v.x() > -3.5f && v.x() < -1.5f && v.y() < 1.15f && v.z() > 5.7f && v.z() < 10.3f;
    // The road and the wall that frame 0 saw behind where the camera ends.
    std::vector<Eigen::Vector3d> road_points, wall_points;
    for (double z = 7; z < 10; z += 0.25) {
      for (double x = -1; x < 3; x += 0.25)
        road_points.push_back(Eigen::Vector3d(x, 1.65, z));
      for (double y = 0; y < 1.5; y += 0.25)
        wall_points.push_back(Eigen::Vector3d(4.0, y, z));
    }
    road[scan_carving] = coveredShare(mesh, road_points, 0.1);
    wall[scan_carving] = coveredShare(mesh, wall_points, 0.1);
    std::printf("  scan carving %d: %zu ghost vertices, road %.3f, wall %.3f\n", scan_carving, ghosts[scan_carving],
                road[scan_carving], wall[scan_carving]);
  }
  EXPECT_GT(ghosts[0], 500u);
  EXPECT_LT(ghosts[1], ghosts[0] / 10);
  // The static street out of view stays, the road at the LiDAR's grazing angles too.
  EXPECT_GE(road[0], 0.98);
  EXPECT_GE(road[1], road[0] - 0.005);
  EXPECT_GE(wall[1], wall[0] - 0.005);
}

TEST(TsdfIntegrator, ScanCarvingKeepsAThinBoardSeenFromBehindByASkewedSweep) {
  // A board 10 cm thick, seen from the front at frame 0, is behind the camera at frame 1,
  // where the LiDAR sees its back. The sweep is not motion-compensated: its returns lie half a
  // metre beyond the board. The board's front surface, a few centimetres behind its back from
  // the LiDAR, must stay.
  const PinholeCamera camera = test::kittiCamera();
  AnalyticScene scene = street(0, -1);
  scene.addBox(Eigen::Vector3d(-1.5, 0.5, 6.0), Eigen::Vector3d(1.0, 1.0, 0.05));
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume);
  integrator.integrate(test::renderFrame(scene, camera, streetPose(0), 0.0), streetPose(0));
  auto board = [&] {
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    std::size_t n = 0;
    for (const auto& v : mesh.vertices)
      n += v.x() > -2.4f && v.x() < -0.6f && v.y() > -0.4f && v.y() < 1.4f && std::abs(v.z() - 6.f) < 0.3f;
    return n;
  };
  const std::size_t before = board();
  const Eigen::Isometry3d T_world_lidar = lidarPose(Eigen::Vector3d(0, 0, 12));
  pcl::PointCloud<pcl::PointXYZI> scan = ringScan(scene, T_world_lidar);
  for (auto& p : scan)
    p.getVector3fMap() *= (p.getVector3fMap().norm() + 0.5f) / p.getVector3fMap().norm();
  const DepthFrame frame = test::renderFrame(scene, camera, streetPose(12), 0.0);
  integrator.integrate(frame, streetPose(12));
  integrator.carveWithScan(ScanFreeSpace(scan), T_world_lidar, 1111.f, frame.camera, streetPose(12));
  const std::size_t after = board();
  std::printf("  board vertices %zu before the skewed scan, %zu after\n", before, after);
  EXPECT_GT(before, 200u);
  EXPECT_GE(after, before * 95 / 100);
}

TEST(TsdfIntegrator, ScanCarvingLeavesWhatTheCameraSeesToTheCamera) {
  // The car stays in view; a scan that sees through it (it is not in the scan's world) must
  // not carve it: in view, the frame's own depth decides.
  const PinholeCamera camera = test::kittiCamera();
  AnalyticScene with_car = street(0, -1);
  with_car.addBox(Eigen::Vector3d(0, 1.65 - 0.75, 10.0), Eigen::Vector3d(0.9, 0.75, 2.2));
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume);
  const DepthFrame frame = test::renderFrame(with_car, camera, streetPose(0), 0.0);
  integrator.integrate(frame, streetPose(0));
  TriangleMesh before, after;
  MarchingCubes().extract(volume, before);
  const Eigen::Isometry3d T_world_lidar = lidarPose(Eigen::Vector3d::Zero());
  integrator.carveWithScan(ScanFreeSpace(ringScan(street(0, -1), T_world_lidar)), T_world_lidar, 1111.f, frame.camera,
                           streetPose(0));
  MarchingCubes().extract(volume, after);
  EXPECT_EQ(after.vertices.size(), before.vertices.size());
  EXPECT_THROW(integrator.carveWithScan(ScanFreeSpace(ringScan(street(0, -1), T_world_lidar)), T_world_lidar, 0.f,
                                        frame.camera, streetPose(0)),
               InvalidInputError);
}

TEST(TsdfIntegrator, ScanCarvingClearsInViewWhereTheCameraCarvesLessThanTheScan) {
  // A car 10 m ahead, seen at frame 0, has left at frame 1, taken from the same place. Frame 1's
  // depth, certain elsewhere, has no pixel where the car was, or a depth there weighing less than
  // the scan (as the fusion's at a car's edge): the camera then carves its old place a little a
  // frame. Its scan sees the road and the wall through the car's place: integrateFrame lets the
  // scan carve wherever the camera carved less. A bollard beside it, which the scan hits, stays.
  const PinholeCamera camera = test::kittiCamera();
  AnalyticScene with_car = street(0, -1), without_car = street(0, -1);
  const Eigen::Vector3d bollard(-2.0, 1.65 - 0.5, 10.0), bollard_half(0.1, 0.5, 0.1);
  with_car.addBox(bollard, bollard_half);
  without_car.addBox(bollard, bollard_half);
  with_car.addBox(Eigen::Vector3d(0, 1.65 - 0.75, 10.0), Eigen::Vector3d(0.9, 0.75, 2.2));
  const DepthFrame seen = test::renderFrame(with_car, camera, streetPose(0), 0.0);
  const DepthFrame left = test::renderFrame(without_car, camera, streetPose(0), 0.0);
  cv::Mat car_pixels = cv::abs(seen.depth - left.depth) > 0.05f;
  cv::dilate(car_pixels, car_pixels, cv::Mat::ones(7, 7, CV_8UC1));
  constexpr float kScanWeight = 1111.f, kCertain = 2000.f, kUncertain = 0.5f; // m^-2
  DepthFrame blank = left, weak = left;
  blank.depth = left.depth.clone();
  blank.depth.setTo(0.f, car_pixels);
  blank.weight = cv::Mat(left.depth.size(), CV_32FC1, cv::Scalar(kCertain));
  weak.weight = blank.weight.clone();
  weak.weight.setTo(kUncertain, car_pixels);
  const Eigen::Isometry3d T_world_lidar = lidarPose(Eigen::Vector3d::Zero());
  const ScanFreeSpace scan(ringScan(without_car, T_world_lidar));

  enum Case { kWholeView, kBlank, kWeak };
  std::size_t car[3] = {0, 0, 0}, bollard_vertices[3] = {0, 0, 0};
  for (const Case c : {kWholeView, kBlank, kWeak}) {
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator integrator(volume);
    integrator.integrate(seen, streetPose(0));
    if (c == kWholeView) {
      integrator.integrate(blank, streetPose(0));
      integrator.carveWithScan(scan, T_world_lidar, kScanWeight, camera, streetPose(0)); // the camera's whole view
    } else {
      TsdfIntegrator::FreeSpace free;
      free.weight = kScanWeight;
      free.scan = &scan;
      free.T_world_lidar = T_world_lidar;
      integrator.integrateFrame(c == kBlank ? blank : weak, streetPose(0), free);
    }
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    for (const auto& v : mesh.vertices) {
      // The car's back, sides and top, half a metre and more above the road; the bollard.
      car[c] += std::abs(v.x()) < 1.0f && v.y() < 1.15f && v.z() > 7.5f && v.z() < 12.5f;
      bollard_vertices[c] += std::abs(v.x() + 2.f) < 0.2f && v.y() < 1.5f && std::abs(v.z() - 10.f) < 0.2f;
    }
    std::printf("  case %d: %zu car vertices, %zu bollard vertices\n", c, car[c], bollard_vertices[c]);
  }
  EXPECT_GT(car[kWholeView], 100u);
  EXPECT_LT(car[kBlank], car[kWholeView] / 10);
  EXPECT_LT(car[kWeak], car[kWholeView] / 10);
  EXPECT_GT(bollard_vertices[kWholeView], 20u);
  for (const Case c : {kBlank, kWeak})
    EXPECT_GE(bollard_vertices[c], bollard_vertices[kWholeView] * 95 / 100);

  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator integrator(volume);
  try {
    integrator.carveWithScan(scan, T_world_lidar, kScanWeight, camera, streetPose(0), cv::Mat(3, 4, CV_32FC1));
    ADD_FAILURE() << "carved weights of another size were taken";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("carved weights must be CV_32FC1 of the camera's " +
                                         std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                                         ", got type 5 of 4x3"),
              std::string::npos)
        << e.what();
  }
}

TEST(TsdfIntegrator, ScanCarvingAllowsForASweepsSkewOnlyInSweptScans) {
  // The back of a car 10 m ahead, seen at frame 0; 0.8 m farther on in the next scan, taken from
  // the same place, where the camera carved nothing. The old back lies 0.5-0.8 m in front of the
  // new returns: within a swept scan's skew, which may have put them there, but not within a
  // scan of one instant's, which clears it.
  const PinholeCamera camera = test::kittiCamera();
  const DepthFrame seen = test::renderFrame(street(0, 10.0), camera, streetPose(0), 0.0);
  const Eigen::Isometry3d T_world_lidar = lidarPose(Eigen::Vector3d::Zero());
  const pcl::PointCloud<pcl::PointXYZI> scan = ringScan(street(0, 10.8), T_world_lidar);
  const cv::Mat carved_nothing = cv::Mat::zeros(camera.height, camera.width, CV_32FC1);
  std::size_t back[2] = {0, 0};
  for (const bool swept : {true, false}) {
    const ScanFreeSpace free_space(scan, swept);
    EXPECT_EQ(free_space.skew(), swept ? ScanFreeSpace::kSweepSkewM : 0.f);
    TsdfVolume volume(0.1, 0.3);
    TsdfIntegrator integrator(volume);
    integrator.integrate(seen, streetPose(0));
    integrator.carveWithScan(free_space, T_world_lidar, 1111.f, camera, streetPose(0), carved_nothing);
    TriangleMesh mesh;
    MarchingCubes().extract(volume, mesh);
    for (const auto& v : mesh.vertices)
      back[swept] += std::abs(v.x()) < 0.8f && v.y() > 0.3f && v.y() < 1.5f && v.z() > 9.8f && v.z() < 10.4f;
  }
  std::printf("  the old back: %zu vertices after a swept scan, %zu after a scan of one instant\n", back[1], back[0]);
  EXPECT_GT(back[1], 100u);
  EXPECT_LT(back[0], back[1] / 10);
}

TEST(TsdfIntegrator, ScanCarvingRangeIsAValidatedKey) {
  TsdfIntegrator::Config c;
  c.scan_carving_m = -1.0;
  try {
    c.validate();
    FAIL() << "a negative scan_carving_m was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scan_carving_m"), std::string::npos) << e.what();
  }
}

namespace {

/// Whether two volumes hold the same blocks with bit-identical voxels.
bool sameVolumes(const TsdfVolume& a, const TsdfVolume& b) {
  if (a.numBlocks() != b.numBlocks())
    return false;
  for (const TsdfBlock* block : a.blocks()) {
    const TsdfBlock* other = b.findBlock(block->index);
    if (!other)
      return false;
    for (int i = 0; i < TsdfBlock::kVoxels; ++i) {
      const TsdfVoxel &x = block->voxels[i], &y = other->voxels[i];
      if (std::memcmp(&x.sdf, &y.sdf, sizeof x.sdf) || std::memcmp(&x.weight, &y.weight, sizeof x.weight) ||
          x.r != y.r || x.g != y.g || x.b != y.b || x.flags != y.flags)
        return false;
    }
    if (block->signs != other->signs || block->negative_subblocks != other->negative_subblocks)
      return false;
  }
  return true;
}

} // namespace

TEST(TsdfIntegrator, ADepthImageInsideAWiderOneAndFramesOfChangingSizesGiveTheSameVolume) {
  // The integrator indexes its depth as rows of the image's width (a view into a wider image is
  // copied first) and keeps its buffers from frame to frame: a frame whose depth is such a view,
  // and frames of two sizes in turn, give bit for bit the volume of plain images integrated
  // by a fresh integrator each time.
  const AnalyticScene scene = test::makeScene(SceneKind::Box);
  const PinholeCamera small = test::smallCamera();
  PinholeCamera large = small;
  large.width = 2 * small.width;
  large.height = small.height + 40;
  large.cx += small.width / 2.0;
  large.cy += 20.0;
  const auto poses = test::arcPoses(Eigen::Vector3d(0, 0, 2.5), 2.5, 15, 4);
  for (const float min_pixel_weight : {0.f, 0.25f}) {
    TsdfIntegrator::Config config;
    config.min_pixel_weight = min_pixel_weight;
    TsdfVolume reused(0.04, 0.12), fresh(0.04, 0.12);
    TsdfIntegrator integrator(reused, config);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const PinholeCamera& camera = i % 2 ? large : small;
      DepthFrame frame = test::renderFrame(scene, camera, poses[i], 0.01, 11 + static_cast<unsigned>(i));
      frame.weight = cv::Mat(frame.depth.size(), CV_32FC1, cv::Scalar(100.f + 10.f * static_cast<float>(i)));
      // The same depth as a view into an image 7 columns wider.
      cv::Mat wider(frame.depth.rows, frame.depth.cols + 7, CV_32FC1, cv::Scalar(5.f));
      frame.depth.copyTo(wider.colRange(3, 3 + frame.depth.cols));
      DepthFrame view = frame;
      view.depth = wider.colRange(3, 3 + frame.depth.cols);
      ASSERT_FALSE(view.depth.isContinuous());
      integrator.integrate(i % 2 ? view : frame, poses[i]);
      TsdfIntegrator(fresh, config).integrate(frame, poses[i]);
    }
    EXPECT_GT(reused.numObservedVoxels(), 1000u);
    EXPECT_TRUE(sameVolumes(reused, fresh)) << "min_pixel_weight " << min_pixel_weight;
  }
}

TEST(TsdfIntegrator, EveryVoxelTestKernelGivesTheSameVolume) {
  // The voxel test and the update of its candidates run 16 (AVX-512), 8 (AVX2) or 4 and 1
  // (portable) voxels at a time, picked by the CPU: each width must give bit for bit the
  // portable kernels' volume, colours and all. Noisy depth, cameras near enough that blocks
  // straddle min_depth_m and the image's edges, and the settings that change the test (space
  // carving: no band in front) or the update (bilinear depth, the plane distance, the weight's
  // drop-off, per-pixel and free-space weights, the regularization's list of changed voxels).
  const int widest = TsdfIntegrator::voxelTestLanes();
  if (widest == 4)
    GTEST_SKIP() << "no wide voxel test on this CPU or build";
  const AnalyticScene scene = test::makeScene(SceneKind::Box);
  const PinholeCamera camera = test::smallCamera();
  const auto poses = test::arcPoses(Eigen::Vector3d(0, 0, 1.2), 1.6, 25, 4);
  std::vector<DepthFrame> frames;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    frames.push_back(test::renderFrame(scene, camera, poses[i], 0.02, 31 + static_cast<unsigned>(i)));
    frames.back().color.create(camera.height, camera.width, CV_8UC3);
    cv::randu(frames.back().color, 0, 255);
  }
  struct Restore {
    ~Restore() { TsdfIntegrator::setMaxVoxelTestLanes(16); }
  } restore;
  for (std::size_t i = 0; i < frames.size(); ++i) { // per-pixel weights, some below min_pixel_weight
    frames[i].weight.create(camera.height, camera.width, CV_32FC1);
    cv::randu(frames[i].weight, 0.f, 400.f);
    frames[i].free_space_weight.create(camera.height, camera.width, CV_32FC1);
    cv::randu(frames[i].free_space_weight, 0.f, 200.f);
  }
  for (const bool carving : {false, true})
    for (const bool bilinear : {false, true})
      for (const auto distance : {TsdfIntegrator::SignedDistance::Plane, TsdfIntegrator::SignedDistance::Projective})
        for (const bool per_pixel : {false, true}) {
          TsdfIntegrator::Config config;
          config.space_carving = carving;
          config.interpolate_depth = bilinear;
          config.signed_distance = distance;
          config.min_depth_m = 0.6;
          if (per_pixel) { // and regularized: the list of changed voxels near a surface, in order
            config.weighting = TsdfIntegrator::Weighting::PerPixel;
            config.min_pixel_weight = 50.f;
            config.weight_dropoff = false;
            config.lambda = 2.0;
            config.lambda_data = TsdfIntegrator::LambdaData::InverseVariance;
          }
          TsdfIntegrator::setMaxVoxelTestLanes(4);
          ASSERT_EQ(TsdfIntegrator::voxelTestLanes(), 4);
          TsdfVolume portable(0.03, 0.09);
          TsdfIntegrator reference(portable, config);
          for (std::size_t i = 0; i < frames.size(); ++i)
            reference.integrate(frames[i], poses[i]);
          ASSERT_GT(portable.numObservedVoxels(), 10000u);
          for (int lanes = 8; lanes <= widest; lanes *= 2) {
            TsdfIntegrator::setMaxVoxelTestLanes(lanes);
            ASSERT_EQ(TsdfIntegrator::voxelTestLanes(), lanes);
            TsdfVolume wide(0.03, 0.09);
            TsdfIntegrator integrator(wide, config);
            for (std::size_t i = 0; i < frames.size(); ++i)
              integrator.integrate(frames[i], poses[i]);
            EXPECT_TRUE(sameVolumes(wide, portable))
                << lanes << " lanes, carving " << carving << ", bilinear " << bilinear << ", " << toString(distance)
                << ", per pixel " << per_pixel;
          }
        }
}

TEST(TsdfIntegrator, TheBandBlocksOfAFrameAreTheBlocksItsIntegrationAllocates) {
  // The street of boxes from KITTI's camera, its depth known to 0.05 m near and 1 m far (the
  // noise widens the far bands), with carving, per-pixel weights and either distance: counting
  // the blocks allocates none, and equals what integrating the frame into an empty volume allocates.
  const AnalyticScene scene = test::corridor(40.0);
  const Eigen::Isometry3d pose = test::lookAt(Eigen::Vector3d(0.3, 0.0, -2.0), Eigen::Vector3d(0.0, 0.5, 30.0));
  DepthFrame frame = test::renderFrame(scene, test::kittiCamera(), pose, 0.02);
  frame.weight = cv::Mat(frame.depth.size(), CV_32FC1);
  for (int v = 0; v < frame.depth.rows; ++v)
    for (int u = 0; u < frame.depth.cols; ++u) {
      const float d = frame.depth.at<float>(v, u);
      frame.weight.at<float>(v, u) = d > 0.f ? (d < 10.f ? 400.f : 1.f) : 0.f;
    }
  for (const auto distance : {TsdfIntegrator::SignedDistance::Projective, TsdfIntegrator::SignedDistance::Plane}) {
    TsdfIntegrator::Config config;
    config.weighting = TsdfIntegrator::Weighting::PerPixel;
    config.signed_distance = distance;
    TsdfVolume counted(0.1, 0.3);
    const std::size_t blocks = TsdfIntegrator(counted, config).bandBlocks(frame, pose);
    EXPECT_EQ(counted.numBlocks(), 0u);
    TsdfVolume integrated(0.1, 0.3);
    TsdfIntegrator(integrated, config).integrate(frame, pose);
    EXPECT_GT(blocks, 500u);
    EXPECT_EQ(blocks, integrated.numBlocks()) << toString(distance);
  }
  // Refused as integrate() refuses: a depth of another type, a pose that is not rigid.
  TsdfVolume untouched(0.1, 0.3);
  TsdfIntegrator counter(untouched);
  DepthFrame wrong = frame;
  wrong.depth = cv::Mat(frame.depth.size(), CV_16UC1, cv::Scalar(1));
  EXPECT_THROW(counter.bandBlocks(wrong, pose), InvalidInputError);
  Eigen::Isometry3d scaled = pose;
  scaled.linear() *= 2.0;
  EXPECT_THROW(counter.bandBlocks(frame, scaled), InvalidInputError);
  EXPECT_EQ(untouched.numBlocks(), 0u);
}
