// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Evaluation protocol 4 on analytic scenes with known answers, and the ghost and crumb metrics
// on hand-made meshes.
#include <msf/common/exceptions.h>
#include <msf/evaluation/crumb_metric.h>
#include <msf/evaluation/ghost_metric.h>
#include <msf/evaluation/reconstruction_evaluation.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>

using namespace msf;

namespace {

PinholeCamera camera() {
  PinholeCamera c;
  c.width = 100, c.height = 80;
  c.fx = c.fy = 100.f;
  c.cx = 49.5f, c.cy = 39.5f;
  return c;
}
constexpr double kFocalBaseline = 100.0 * 0.5; // f = 100 px, B = 0.5 m

/// A square of side `side` facing the camera at depth z, centred on the world point (x, y).
TriangleMesh square(float x, float y, float z, float side) {
  TriangleMesh mesh;
  const float h = side / 2;
  mesh.vertices = {{x - h, y - h, z}, {x + h, y - h, z}, {x + h, y + h, z}, {x - h, y + h, z}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

cv::Mat constantDepth(float z) { return cv::Mat(80, 100, CV_32FC1, cv::Scalar(z)); }

/// `pieces` side by side in one mesh, each a connected piece of its own.
TriangleMesh joined(const std::vector<TriangleMesh>& pieces) {
  TriangleMesh mesh;
  for (const TriangleMesh& piece : pieces) {
    const auto offset = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), piece.vertices.begin(), piece.vertices.end());
    for (const auto& t : piece.triangles)
      mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  mesh.colors.resize(mesh.vertices.size());
  return mesh;
}

/// A strip of 2 n triangles along x, from (x, y, z) to (x + n step, y + step, z): one piece.
TriangleMesh strip(float x, float y, float z, int n, float step) {
  TriangleMesh mesh;
  for (int i = 0; i <= n; ++i) {
    mesh.vertices.push_back({x + i * step, y, z});
    mesh.vertices.push_back({x + i * step, y + step, z});
  }
  for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(n); ++i) {
    mesh.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 1});
    mesh.triangles.push_back({2 * i + 1, 2 * i + 2, 2 * i + 3});
  }
  return mesh;
}

/// Pixels whose centre sees the world point x in [x0, x1], y in [y0, y1] at depth z, from the origin.
int footprint(float z, float x0, float x1, float y0, float y1) {
  const PinholeCamera c = camera();
  int n = 0;
  for (int v = 0; v < c.height; ++v)
    for (int u = 0; u < c.width; ++u) {
      const double x = (u - c.cx) * z / c.fx, y = (v - c.cy) * z / c.fy;
      n += x >= x0 && x <= x1 && y >= y0 && y <= y1;
    }
  return n;
}

/// The LiDAR beside the camera, x forward and z up (KITTI's axes): T_cam_lidar.
Eigen::Isometry3d cameraFromLidar() {
  Eigen::Matrix3d lidar_from_cam;
  lidar_from_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = lidar_from_cam.transpose();
  return T;
}

/// The scan, in the LiDAR's frame, of what the camera sees as `depth`: a return every third of a
/// pixel, denser than the free space's bins.
ScanFreeSpace scanOf(const cv::Mat& depth) {
  const PinholeCamera c = camera();
  const Eigen::Isometry3d T_lidar_cam = cameraFromLidar().inverse();
  pcl::PointCloud<pcl::PointXYZI> scan;
  for (float v = 0; v < c.height; v += 1.f / 3)
    for (float u = 0; u < c.width; u += 1.f / 3) {
      const double z = depth.at<float>(static_cast<int>(v), static_cast<int>(u));
      const Eigen::Vector3d p = T_lidar_cam * Eigen::Vector3d((u - c.cx) * z / c.fx, (v - c.cy) * z / c.fy, z);
      pcl::PointXYZI point;
      point.getVector3fMap() = p.cast<float>();
      scan.push_back(point);
    }
  return ScanFreeSpace(scan);
}

} // namespace

TEST(ReconstructionEvaluation, AReturnAScanOfAnotherFrameSawThroughIsTransient) {
  // Frame 0 sees a car at 5 m in the lower left quarter (2000 pixels) before a wall at 10 m; a
  // frame later, from the same place, the car has left and the scan sees the wall there.
  cv::Mat with_car = constantDepth(10.f);
  with_car(cv::Rect(0, 40, 50, 40)).setTo(5.f);
  const Eigen::Isometry3d T_world_lidar = cameraFromLidar();
  ReconstructionEvaluation evaluation(camera(), kFocalBaseline, 40.0);
  evaluation.addGroundTruth(0, Eigen::Isometry3d::Identity(), with_car);
  // A frame's own scan is not asked: its returns and the held-out ones are one sweep's.
  evaluation.addScan(0, T_world_lidar, scanOf(constantDepth(10.f)));
  EXPECT_TRUE(evaluation.splitsTransient());
  evaluation.scoreDepth("map", 0, constantDepth(10.f));
  EXPECT_EQ(evaluation.scores().at(0).transient_within_range.gt_pixels, 0u);
  evaluation.addScan(1, T_world_lidar, scanOf(constantDepth(10.f)));
  const ReconstructionScore s = evaluation.scores().at(0);
  EXPECT_EQ(s.within_range.gt_pixels, 8000u);
  EXPECT_EQ(s.transient_within_range.gt_pixels, 2000u);
  EXPECT_EQ(s.lasting_within_range.gt_pixels, 6000u);
  EXPECT_DOUBLE_EQ(s.lasting_within_range.d1_all, 0.0);
  EXPECT_DOUBLE_EQ(s.transient_within_range.d1_all, 1.0); // a map of what stays holds the wall there
  EXPECT_DOUBLE_EQ(s.within_range.d1_all, 0.25);            // the static figures are as before

  // A scan may come before the ground truth it sees through; not from beyond the window.
  ReconstructionEvaluation later(camera(), kFocalBaseline, 40.0);
  EXPECT_FALSE(later.splitsTransient());
  later.addScan(0, T_world_lidar, scanOf(constantDepth(10.f)));
  later.addGroundTruth(ReconstructionEvaluation::kScanWindow, Eigen::Isometry3d::Identity(), with_car);
  later.addGroundTruth(ReconstructionEvaluation::kScanWindow + 1, Eigen::Isometry3d::Identity(), with_car);
  later.scoreDepth("map", ReconstructionEvaluation::kScanWindow, constantDepth(10.f));
  later.scoreDepth("map", ReconstructionEvaluation::kScanWindow + 1, constantDepth(10.f));
  EXPECT_EQ(later.scores().at(0).transient_within_range.gt_pixels, 2000u);
  EXPECT_THROW(later.addScan(2, Eigen::Isometry3d(Eigen::Matrix4d::Constant(NAN)), scanOf(with_car)),
               InvalidInputError);
}

TEST(ReconstructionEvaluation, AMeshOffsetFromThePlaneHasThatErrorOverItsFootprint) {
  // Ground truth: a wall at 10 m over the whole image. The mesh: a 4 m square of it, 0.1 m
  // behind. The fused depth: the wall 0.05 m in front, everywhere.
  ReconstructionEvaluation evaluation(camera(), kFocalBaseline, 40.0);
  evaluation.addGroundTruth(0, Eigen::Isometry3d::Identity(), constantDepth(10.f));
  evaluation.scoreDepth("fused", 0, constantDepth(9.95f));
  evaluation.scoreMesh("mesh", square(0.f, 0.f, 10.1f, 4.f));
  const auto scores = evaluation.scores();
  ASSERT_EQ(scores.size(), 2u);
  EXPECT_EQ(scores[0].source, "fused");
  EXPECT_EQ(scores[1].source, "mesh");
  const DepthMetrics& fused = scores[0].all;
  EXPECT_EQ(fused.gt_pixels, 8000u);
  EXPECT_DOUBLE_EQ(fused.coverage, 1.0);
  EXPECT_NEAR(fused.mae_m, 0.05, 1e-5);
  EXPECT_DOUBLE_EQ(fused.d1_all, 0.0);
  const DepthMetrics& mesh = scores[1].all;
  // The square covers 4 m / 10.1 m * 100 px ~ 40 px a side.
  const int covered = footprint(10.1f, -2.f, 2.f, -2.f, 2.f);
  EXPECT_GT(covered, 1500);
  EXPECT_EQ(mesh.gt_pixels, 8000u);
  EXPECT_EQ(mesh.estimated, static_cast<std::size_t>(covered));
  EXPECT_NEAR(mesh.coverage, covered / 8000.0, 1e-12);
  EXPECT_NEAR(mesh.mae_m, 0.1, 1e-5);
  EXPECT_NEAR(mesh.rmse_m, 0.1, 1e-5);
  EXPECT_NEAR(mesh.d1_all, 1.0 - covered / 8000.0, 1e-12); // missing = bad; 0.05 px off is good
  EXPECT_DOUBLE_EQ(mesh.d1_estimated, 0.0);
  // Everything within range: the same figures; nothing moving.
  EXPECT_EQ(scores[1].within_range.gt_pixels, 8000u);
  EXPECT_EQ(scores[1].within_range.estimated, mesh.estimated);
  EXPECT_EQ(scores[1].moving_all.gt_pixels, 0u);
  EXPECT_EQ(evaluation.frames(), 1u);
  EXPECT_EQ(evaluation.groundTruthPixels(), 8000u);
}

TEST(ReconstructionEvaluation, RangeMovingPixelsAndPosesSplitThePixels) {
  // Two frames seeing the same wall from 10 m and, moved 20 m back, from 30 m; the range is
  // 20 m. In frame 1, the left half of the image is a moving object.
  ReconstructionEvaluation evaluation(camera(), kFocalBaseline, 20.0);
  evaluation.addGroundTruth(0, Eigen::Isometry3d::Identity(), constantDepth(10.f));
  Eigen::Isometry3d back = Eigen::Isometry3d::Identity();
  back.translation().z() = -20.0;
  cv::Mat moving(80, 100, CV_8UC1, cv::Scalar(0));
  moving.colRange(0, 50).setTo(255);
  // Sparse ground truth, as the held-out rings are: every other row.
  cv::Mat sparse = constantDepth(30.f);
  for (int v = 1; v < 80; v += 2)
    sparse.row(v).setTo(0.f);
  evaluation.addGroundTruth(1, back, sparse, moving);
  EXPECT_EQ(evaluation.groundTruthPixels(), 8000u + 4000u);
  // The wall itself, large enough to fill both views.
  evaluation.scoreMesh("mesh", square(0.f, 0.f, 10.f, 40.f));
  const ReconstructionScore s = evaluation.scores().at(0);
  EXPECT_EQ(s.all.gt_pixels, 8000u + 2000u);     // frame 1's right half is static
  EXPECT_EQ(s.within_range.gt_pixels, 8000u);    // frame 1's wall is 30 m away
  EXPECT_EQ(s.moving_all.gt_pixels, 2000u);
  EXPECT_EQ(s.moving_within_range.gt_pixels, 0u);
  EXPECT_DOUBLE_EQ(s.all.coverage, 1.0);
  EXPECT_LT(s.all.mae_m, 1e-4); // the mesh is rendered at each frame's own pose
  EXPECT_DOUBLE_EQ(s.moving_all.coverage, 1.0);
}

TEST(ReconstructionEvaluation, BadInputIsAClearError) {
  EXPECT_THROW(ReconstructionEvaluation(PinholeCamera(), kFocalBaseline, 40.0), InvalidInputError);
  EXPECT_THROW(ReconstructionEvaluation(camera(), 0.0, 40.0), InvalidInputError);
  EXPECT_THROW(ReconstructionEvaluation(camera(), kFocalBaseline, 0.0), ConfigError);
  ReconstructionEvaluation evaluation(camera(), kFocalBaseline, 40.0);
  auto message = [](const auto& call) {
    try {
      call();
    } catch (const InvalidInputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(message([&] { evaluation.scoreDepth("fused", 3, constantDepth(1.f)); })
                .find("frame 3 has no ground truth"),
            std::string::npos);
  EXPECT_NE(message([&] { evaluation.addGroundTruth(0, Eigen::Isometry3d::Identity(), cv::Mat(10, 10, CV_32FC1)); })
                .find("ground truth of frame 0 is a 10x10 image"),
            std::string::npos);
  evaluation.addGroundTruth(0, Eigen::Isometry3d::Identity(), constantDepth(5.f));
  EXPECT_NE(message([&] { evaluation.addGroundTruth(0, Eigen::Isometry3d::Identity(), constantDepth(5.f)); })
                .find("given twice"),
            std::string::npos);
  EXPECT_NE(message([&] { evaluation.scoreDepth("fused", 0, cv::Mat(80, 100, CV_16UC1)); }).find("fused depth of frame 0"),
            std::string::npos);
}

TEST(GhostMetric, CountsVerticesFarFromTheStaticSurfaceWhereAMovingObjectWas) {
  // The static surface: the ground y = 0. A car drove through the box x in [0, 2],
  // y in [-2, 0], z in [5, 9] (world y down: the box stands on the ground).
  const SurfaceDistance ground({{-50.f, 0.f, -50.f}, {50.f, 0.f, -50.f}, {50.f, 0.f, 50.f}, {-50.f, 0.f, 50.f}},
                               {{0, 1, 2}, {0, 2, 3}});
  const MovingSpace was_moving = [](const Eigen::Vector3f& p) {
    return p.x() >= 0.f && p.x() <= 2.f && p.y() >= -2.f && p.y() <= 0.f && p.z() >= 5.f && p.z() <= 9.f;
  };
  const std::vector<Eigen::Vector3f> vertices = {
      {1.f, 0.f, 6.f},     // the road under the car: not a ghost
      {1.f, -1.f, 6.f},    // the car's side left in the map: a ghost
      {1.f, -0.15f, 7.f},  // within 0.2 m of the road: not a ghost
      {1.f, -0.25f, 7.f},  // 0.25 m above it: a ghost
      {5.f, -1.f, 6.f},    // a floating speck where no car was: not a ghost
  };
  const GhostMetrics m = measureGhosts(vertices, ground, was_moving, 0.2);
  EXPECT_EQ(m.vertices, 5u);
  EXPECT_EQ(m.ghost_vertices, 2u);
  EXPECT_DOUBLE_EQ(m.share, 0.4);
  EXPECT_DOUBLE_EQ(m.distance_m, 0.2);
  // A larger distance keeps only the side.
  EXPECT_EQ(measureGhosts(vertices, ground, was_moving, 0.5).ghost_vertices, 1u);
  EXPECT_THROW(measureGhosts(vertices, ground, MovingSpace(), 0.2), InvalidInputError);
  EXPECT_THROW(measureGhosts(vertices, ground, was_moving, 0.0), InvalidInputError);
  EXPECT_EQ(measureGhosts({}, ground, was_moving).share, 0.0);
}

TEST(CrumbMetric, CountsSmallPiecesOffTheStaticSurfaceWhereAMovingObjectWas) {
  // The static surface: the ground y = 0 and a bollard's face, the square x in [9.9, 10.1],
  // y in [-1, 0] at z = 5. A car drove through the box x in [0, 2], y in [-2, 0], z in [5, 9].
  const SurfaceDistance truth({{-50.f, 0.f, -50.f}, {50.f, 0.f, -50.f}, {50.f, 0.f, 50.f}, {-50.f, 0.f, 50.f},
                               {9.9f, -1.f, 5.f}, {10.1f, -1.f, 5.f}, {10.1f, 0.f, 5.f}, {9.9f, 0.f, 5.f}},
                              {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}});
  const MovingSpace was_moving = [](const Eigen::Vector3f& p) {
    return p.x() >= 0.f && p.x() <= 2.f && p.y() >= -2.f && p.y() <= 0.f && p.z() >= 5.f && p.z() <= 9.f;
  };
  const TriangleMesh mesh = joined({
      strip(0.5f, -1.f, 6.f, 3, 0.1f),      // a crumb of the car, 1 m above the road: 6 triangles
      strip(0.5f, -1.f, 7.f, 30, 0.04f),    // the car's side, 60 triangles: a ghost, not a crumb
      strip(9.9f, -0.5f, 5.f, 2, 0.1f),     // the bollard's face: small, on the static surface
      strip(0.5f, -0.05f, 8.f, 3, 0.1f),    // the road under the car: small, within 0.2 m of it
      strip(20.f, -3.f, 6.f, 2, 0.1f),      // a floating speck where no car was
      strip(-20.f, 0.f, 6.f, 40, 0.1f),     // the road: a large piece
  });
  const CrumbMetrics m = measureCrumbs(mesh, truth, was_moving, 50, 0.2);
  EXPECT_EQ(m.pieces, 6u);
  EXPECT_EQ(m.small_pieces, 4u);
  EXPECT_EQ(m.crumbs, 1u);
  EXPECT_EQ(m.crumb_triangles, 6u);
  EXPECT_EQ(m.specks, 1u);
  EXPECT_EQ(m.max_triangles, 50u);
  EXPECT_DOUBLE_EQ(m.distance_m, 0.2);
  // Under a larger bar for "small", the car's side is a crumb too.
  EXPECT_EQ(measureCrumbs(mesh, truth, was_moving, 100, 0.2).crumbs, 2u);
  EXPECT_THROW(measureCrumbs(mesh, truth, MovingSpace(), 50, 0.2), InvalidInputError);
  EXPECT_THROW(measureCrumbs(mesh, truth, was_moving, 50, 0.0), InvalidInputError);
  EXPECT_THROW(measureCrumbs(mesh, truth, was_moving, 0, 0.2), InvalidInputError);
  EXPECT_TRUE(m.by_frames_since_left.empty()); // not asked for
}

TEST(CrumbMetric, CountsTheCrumbsByTheFramesSinceTheirPlaceWasLeft) {
  // The ground y = 0. A car drove through the box x in [0, 2], y in [-2, 0], z in [5, 12]: it
  // left z < 7 five frames before the last one, z in [7, 10) two frames before, z >= 10 one
  // frame before.
  const SurfaceDistance ground({{-50.f, 0.f, -50.f}, {50.f, 0.f, -50.f}, {50.f, 0.f, 50.f}, {-50.f, 0.f, 50.f}},
                               {{0, 1, 2}, {0, 2, 3}});
  const FramesSinceLeft since_left = [](const Eigen::Vector3f& p) -> std::size_t {
    const bool inside = p.x() >= 0.f && p.x() <= 2.f && p.y() >= -2.f && p.y() <= 0.f && p.z() >= 5.f && p.z() <= 12.f;
    return !inside ? 0 : p.z() < 7.f ? 5 : p.z() < 10.f ? 2 : 1;
  };
  const MovingSpace was_moving = [&](const Eigen::Vector3f& p) { return since_left(p) > 0; };
  const TriangleMesh mesh = joined({
      strip(0.5f, -1.f, 6.f, 3, 0.1f),  // left five frames ago
      strip(0.5f, -1.f, 8.f, 3, 0.1f),  // two
      strip(0.5f, -1.f, 11.f, 3, 0.1f), // one
      strip(0.5f, -1.5f, 11.5f, 2, 0.1f), // one
      strip(20.f, -3.f, 6.f, 2, 0.1f),  // a speck where no car was: not counted
  });
  const CrumbMetrics m = measureCrumbs(mesh, ground, was_moving, 50, 0.2, since_left, 3);
  EXPECT_EQ(m.crumbs, 4u);
  EXPECT_EQ(m.specks, 1u);
  EXPECT_EQ(m.by_frames_since_left, (std::vector<std::size_t>{2, 1, 1})); // 1, 2, 3 or more frames
  // Two buckets: 1, and 2 or more.
  EXPECT_EQ(measureCrumbs(mesh, ground, was_moving, 50, 0.2, since_left, 2).by_frames_since_left,
            (std::vector<std::size_t>{2, 2}));
  EXPECT_THROW(measureCrumbs(mesh, ground, was_moving, 50, 0.2, since_left, 0), InvalidInputError);
}

TEST(ReconstructionEvaluation, SmallPiecesInFrontOfTheTrueDepthAreSeenThrough) {
  // Ground truth: a wall at 10 m. A small piece floats at 5 m (the truth lies behind it: seen
  // through), another lies on the wall, a large piece floats at 5 m, a small one is out of view.
  ReconstructionEvaluation evaluation(camera(), kFocalBaseline, 40.0);
  evaluation.addGroundTruth(0, Eigen::Isometry3d::Identity(), constantDepth(10.f));
  const TriangleMesh mesh = joined({
      strip(-1.f, -1.f, 5.f, 4, 0.1f),      // 8 triangles in front of the wall
      strip(1.f, 1.f, 10.f, 4, 0.1f),       // 8 triangles on it
      strip(-2.f, 0.5f, 5.f, 30, 0.02f),    // 60 triangles in front of it
      strip(100.f, 0.f, 5.f, 4, 0.1f),      // out of the image
  });
  const SeenThroughPieces seen = evaluation.seenThroughPieces(mesh, 50);
  EXPECT_EQ(seen.pieces, 4u);
  EXPECT_EQ(seen.small_pieces, 3u);
  EXPECT_EQ(seen.seen_through, 1u);
  EXPECT_EQ(seen.triangles, 8u);
  EXPECT_EQ(seen.max_triangles, 50u);
  // A bar above 60 triangles takes in the large piece too; a wall at 5.05 m is within D1.
  EXPECT_EQ(evaluation.seenThroughPieces(mesh, 61).seen_through, 2u);
  ReconstructionEvaluation near_wall(camera(), kFocalBaseline, 40.0);
  near_wall.addGroundTruth(0, Eigen::Isometry3d::Identity(), constantDepth(5.05f));
  EXPECT_EQ(near_wall.seenThroughPieces(mesh, 50).seen_through, 0u);
  EXPECT_THROW(evaluation.seenThroughPieces(mesh, 0), InvalidInputError);
}
