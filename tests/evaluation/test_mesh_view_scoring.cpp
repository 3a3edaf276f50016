// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The mesh's views shared by its scorers: each camera and pose rendered once, handed to every
// scorer of it in frame order, the same rendering a scorer makes alone; protocols 4 and 6
// scored through shared views give what each gives alone.
#include <msf/common/exceptions.h>
#include <msf/evaluation/mesh_view_scoring.h>
#include <msf/evaluation/open_sky_coverage.h>
#include <msf/evaluation/reconstruction_evaluation.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <utility>
#include <vector>

using namespace msf;

namespace {

PinholeCamera camera(float f = 100.f) {
  PinholeCamera c;
  c.width = 100, c.height = 80;
  c.fx = c.fy = f;
  c.cx = 49.5f, c.cy = 39.5f;
  return c;
}

/// A 6 m square facing the camera at 10 m, and a 2 m one in front of its corner at 6 m.
TriangleMesh twoSquares() {
  TriangleMesh mesh;
  mesh.vertices = {{-3, -3, 10}, {3, -3, 10}, {3, 3, 10}, {-3, 3, 10}, {0, 0, 6}, {2, 0, 6}, {2, 2, 6}, {0, 2, 6}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  return mesh;
}

Eigen::Isometry3d shifted(double x, double y) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << x, y, 0.0;
  return T;
}

/// The frames a scorer was handed, in order, each with whether its rendering is the one a
/// rasterizer of its own makes.
struct Seen {
  std::vector<std::pair<std::size_t, bool>> frames;
};

MeshViewScoring::Scorer recorder(Seen& seen, const TriangleMesh& mesh, const PinholeCamera& c,
                                 const std::map<std::size_t, Eigen::Isometry3d>& views) {
  return [&seen, &mesh, c, views](std::size_t frame, const cv::Mat& rendered) {
    MeshRasterizer alone;
    cv::Mat expected;
    alone.render(mesh, c, views.at(frame), expected);
    const bool same = cv::norm(rendered, expected, cv::NORM_INF) == 0.0 && cv::countNonZero(expected) > 0;
    seen.frames.emplace_back(frame, same);
  };
}

} // namespace

TEST(MeshViewScoring, EachCameraAndPoseIsRenderedOnceForEveryScorerOfIt) {
  const TriangleMesh mesh = twoSquares();
  // a: frames 0 and 1; b: frames 1 (a's pose) and 2; c: frame 1 from a's pose through
  // another camera; d: frame 1 through a's camera from another pose.
  const std::map<std::size_t, Eigen::Isometry3d> a_views = {{0, shifted(0, 0)}, {1, shifted(0.5, 0)}},
                                                 b_views = {{1, shifted(0.5, 0)}, {2, shifted(1, 0)}},
                                                 c_views = {{1, shifted(0.5, 0)}}, d_views = {{1, shifted(0, 0.5)}};
  Seen a, b, c, d;
  MeshViewScoring scoring;
  scoring.add(camera(), a_views, recorder(a, mesh, camera(), a_views));
  scoring.add(camera(), b_views, recorder(b, mesh, camera(), b_views));
  scoring.add(camera(80.f), c_views, recorder(c, mesh, camera(80.f), c_views));
  scoring.add(camera(), d_views, recorder(d, mesh, camera(), d_views));
  EXPECT_EQ(scoring.views(), 5u) << "frame 0; frame 1 shared by a and b, c's camera, d's pose; frame 2";
  EXPECT_EQ(scoring.score(mesh), 5u);
  using Frames = std::vector<std::pair<std::size_t, bool>>;
  EXPECT_EQ(a.frames, (Frames{{0, true}, {1, true}}));
  EXPECT_EQ(b.frames, (Frames{{1, true}, {2, true}}));
  EXPECT_EQ(c.frames, (Frames{{1, true}}));
  EXPECT_EQ(d.frames, (Frames{{1, true}}));
}

TEST(MeshViewScoring, AViewWhoseScorersReadTheTopRowsRendersOnlyThoseAndTheyMatchTheFullImage) {
  const TriangleMesh mesh = twoSquares();
  const std::map<std::size_t, Eigen::Isometry3d> views = {{0, shifted(0, 0)}, {1, shifted(0.5, 0)}};
  MeshRasterizer alone;
  std::map<std::size_t, cv::Mat> full;
  for (const auto& [frame, pose] : views)
    alone.render(mesh, camera(), pose, full[frame]);
  // Frame 0: a scorer of its top 30 rows alone; frame 1: beside one that reads every row.
  std::map<std::size_t, cv::Size> top_seen, all_seen;
  std::map<std::size_t, bool> same;
  MeshViewScoring scoring;
  scoring.add(camera(), views, [&](std::size_t frame, const cv::Mat& rendered) {
    top_seen[frame] = rendered.size();
    same[frame] = cv::norm(rendered, full[frame].rowRange(0, rendered.rows), cv::NORM_INF) == 0.0;
  }, {{0, 30}, {1, 30}});
  scoring.add(camera(), {{1, views.at(1)}}, [&](std::size_t frame, const cv::Mat& rendered) {
    all_seen[frame] = rendered.size();
  });
  EXPECT_EQ(scoring.score(mesh), 2u);
  EXPECT_EQ(top_seen[0], cv::Size(100, 30));
  EXPECT_EQ(top_seen[1], cv::Size(100, 80)) << "the view's other scorer reads every row";
  EXPECT_EQ(all_seen[1], cv::Size(100, 80));
  EXPECT_TRUE(same[0]);
  EXPECT_TRUE(same[1]);
  EXPECT_GT(cv::countNonZero(full[0].rowRange(0, 30)), 0) << "the top rows hold surface";
  EXPECT_THROW(scoring.add(camera(), views, [](std::size_t, const cv::Mat&) {}, {{0, 81}}), InvalidInputError);
  EXPECT_THROW(scoring.add(camera(), views, [](std::size_t, const cv::Mat&) {}, {{0, 0}}), InvalidInputError);
}

TEST(MeshViewScoring, ProtocolsFourAndSixThroughSharedViewsScoreAsAlone) {
  // Three frames along x; the truth a wall at 10 m; the sky the top 20 rows.
  const TriangleMesh mesh = twoSquares();
  ReconstructionEvaluation evaluation(camera(), 50.0, 40.0);
  OpenSkyCoverage sky(camera());
  cv::Mat mask(80, 100, CV_8UC1, cv::Scalar(0));
  mask.rowRange(0, 20).setTo(255);
  const cv::Mat wall(80, 100, CV_32FC1, cv::Scalar(10.f));
  for (std::size_t i = 0; i < 3; ++i) {
    evaluation.addGroundTruth(i, shifted(0.5 * static_cast<double>(i), 0), wall);
    sky.addMask(i, mask);
    sky.setPose(i, shifted(0.5 * static_cast<double>(i), 0));
  }
  evaluation.scoreMesh("alone", mesh);
  const SkyCoverage sky_alone = sky.scoreMesh(mesh);

  MeshViewScoring scoring;
  evaluation.addViews(scoring, "shared");
  OpenSkyCoverage::Tally tally;
  sky.addViews(scoring, tally);
  EXPECT_EQ(scoring.views(), 3u);
  EXPECT_EQ(scoring.score(mesh), 3u);

  const auto rows = evaluation.scores();
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_GT(rows[0].all.estimated, 0u);
  EXPECT_LT(rows[0].all.coverage, 1.0);
  EXPECT_EQ(rows[1].all.estimated, rows[0].all.estimated);
  EXPECT_EQ(rows[1].all.mae_m, rows[0].all.mae_m);
  EXPECT_EQ(rows[1].all.d1_all, rows[0].all.d1_all);
  const SkyCoverage shared = tally.coverage();
  EXPECT_GT(sky_alone.covered_pixels, 0u);
  EXPECT_EQ(shared.frames, 3u);
  EXPECT_EQ(shared.covered_pixels, sky_alone.covered_pixels);
  EXPECT_EQ(shared.frame_share, sky_alone.frame_share);
  EXPECT_EQ(shared.covered_depth_median_m, sky_alone.covered_depth_median_m);
}

TEST(MeshViewScoring, AnInvalidCameraOrPoseIsAClearError) {
  MeshViewScoring scoring;
  const auto none = [](std::size_t, const cv::Mat&) {};
  try {
    scoring.add(PinholeCamera(), {{0, Eigen::Isometry3d::Identity()}}, none);
    FAIL() << "an invalid camera was taken";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh views: invalid camera (0x0 px"), std::string::npos) << e.what();
  }
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::nan("");
  try {
    scoring.add(camera(), {{0, Eigen::Isometry3d::Identity()}, {7, bad}}, none);
    FAIL() << "a pose that is not finite was taken";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("the pose of frame 7 is not finite"), std::string::npos) << e.what();
  }
  EXPECT_EQ(scoring.views(), 0u) << "a refused scorer adds no view";
}
