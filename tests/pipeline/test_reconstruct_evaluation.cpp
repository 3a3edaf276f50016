// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_reconstruct's evaluation protocol 4: -holdout on real KITTI frames, the synthetic
// ground truth with moving objects marked, -compare_sources, -compare_paper, and clear errors
// that leave no output.
#include <msf/io/image_io.h>
#include <msf/io/velodyne_io.h>
#include <msf/synthetic/ground_truth.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace {

/// msf_reconstruct of a dataset with `options` into `out` (its figures only, -panels 0): what
/// it printed, and its summary.json ("" after a failure, reported with its stderr).
struct Reconstruction {
  msf::test::CommandResult run;
  std::string summary;
};
Reconstruction reconstruct(const std::string& dataset, const std::string& options, const msf::test::TempDir& out) {
  Reconstruction r{msf::test::runTool("msf_reconstruct", dataset + " " + options + " -panels 0 -o " + out.path()), ""};
  EXPECT_EQ(r.run.exit_code, 0) << r.run.err;
  if (r.run.exit_code == 0)
    r.summary = readFile(out.file("summary.json"));
  return r;
}

/// KITTI odometry 04 as a dataset of its own under `root`, its folders linked: without the
/// poses when `poses` is false; with the scans of frames 0-1 sorted by azimuth (one sweep,
/// no ring order) when `sorted_scans` is true.
std::string kittiCopy(const std::string& root, bool poses, bool sorted_scans) {
  const fs::path kitti = fs::path(msf::test::kittiDir()) / "odometry";
  const fs::path sequence = fs::path(root) / "sequences" / "04";
  fs::create_directories(sequence);
  for (const char* entry : {"image_0", "image_1", "image_2", "calib.txt", "times.txt"})
    fs::create_symlink(kitti / "sequences" / "04" / entry, sequence / entry);
  if (poses) {
    fs::create_directories(fs::path(root) / "poses");
    fs::create_symlink(kitti / "poses" / "04.txt", fs::path(root) / "poses" / "04.txt");
  }
  if (!sorted_scans) {
    fs::create_symlink(kitti / "sequences" / "04" / "velodyne", sequence / "velodyne");
  } else {
    fs::create_directories(sequence / "velodyne");
    for (const char* name : {"000000.bin", "000001.bin"}) {
      pcl::PointCloud<pcl::PointXYZI> scan;
      msf::loadVelodyneBin((kitti / "sequences" / "04" / "velodyne" / name).string(), scan);
      std::sort(scan.begin(), scan.end(), [](const pcl::PointXYZI& a, const pcl::PointXYZI& b) {
        return std::atan2(a.y, a.x) < std::atan2(b.y, b.x);
      });
      msf::saveVelodyneBin((sequence / "velodyne" / name).string(), scan);
    }
  }
  return sequence.string();
}

/// The JSON object of one protocol 4 row ("mesh", "fused", ...) with its metrics.
std::string rowOf(const std::string& json, const std::string& source) {
  const std::size_t rows = json.find("\"rows\"", json.find("\"reconstruction_evaluation\""));
  const std::size_t at = json.find("\"" + source + "\": {", rows);
  return at == std::string::npos ? "" : json.substr(at, json.find("\n      }", at) - at);
}

} // namespace

TEST(ReconstructEvaluation, HoldoutOnKittiScoresTheMeshesBesideTheFusedDepth) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir out;
  const std::string sequence = msf::test::kittiDir() + "/odometry/sequences/04";
  const auto r = msf::test::runTool("msf_reconstruct", sequence + " -frames 0:1 -holdout -compare_sources -panels 0 -o " +
                                                           out.path() + " -config " + msf::test::sourceDir() +
                                                           "/config/kitti.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string json = readFile(out.file("summary.json"));
  EXPECT_NE(json.find("\"truth\": \"held-out rings (ring id % 4 == 2)"), std::string::npos);
  EXPECT_EQ(jsonNumber(json, "frames", "reconstruction_evaluation"), 2);
  EXPECT_EQ(jsonNumber(json, "range_m", "reconstruction_evaluation"), 40); // kitti.yaml's tsdf_integrator.max_depth_m
  const double pixels = jsonNumber(json, "gt_pixels", "reconstruction_evaluation");
  EXPECT_GT(pixels, 8000);
  for (const char* source : {"mesh", "fused", "mesh_lidar", "mesh_stereo"}) {
    const std::string row = rowOf(json, source);
    ASSERT_FALSE(row.empty()) << source << " row missing:\n" << json;
    // Every row is scored at the same pixels.
    EXPECT_EQ(jsonNumber(row, "gt_pixels", "all"), pixels) << source;
    EXPECT_LE(jsonNumber(row, "gt_pixels", "within_range"), pixels) << source;
    EXPECT_GT(jsonNumber(row, "coverage", "within_range"), 0.05) << source;
    EXPECT_LE(jsonNumber(row, "d1_all", "within_range"), 1.0) << source;
  }
  // The fused depth covers (nearly) every held-out pixel; a two-frame map far fewer, and
  // its missing pixels count as bad.
  const double fused_coverage = jsonNumber(rowOf(json, "fused"), "coverage", "within_range");
  const double mesh_coverage = jsonNumber(rowOf(json, "mesh"), "coverage", "within_range");
  EXPECT_GT(fused_coverage, 0.99);
  EXPECT_LT(mesh_coverage, fused_coverage);
  EXPECT_GT(jsonNumber(rowOf(json, "mesh"), "d1_all", "within_range"),
            jsonNumber(rowOf(json, "fused"), "d1_all", "within_range"));
  // Where the mesh has depth, it is the held-out surface most of the time.
  EXPECT_LT(jsonNumber(rowOf(json, "mesh"), "d1_estimated", "within_range"), 0.2);
  // Its small pieces the held-out rings see through: some of its small pieces, at most.
  const std::string mesh_row = rowOf(json, "mesh");
  const double small_pieces = jsonNumber(mesh_row, "small_pieces", "seen_through");
  EXPECT_GT(small_pieces, 0.0);
  EXPECT_LE(small_pieces, jsonNumber(mesh_row, "all_pieces", "seen_through"));
  EXPECT_LE(jsonNumber(mesh_row, "pieces", "seen_through"), small_pieces);
  EXPECT_EQ(jsonNumber(mesh_row, "max_triangles", "seen_through"), 50);
  // The scans split the pixels in range: where frame 1's scan saw through frame 0's held-out
  // returns (the van ahead moved on), the per-frame depth has the van and the map has not.
  EXPECT_NE(json.find("\"transient_split\": true"), std::string::npos);
  for (const char* source : {"mesh", "fused"}) {
    const std::string row = rowOf(json, source);
    const double lasting = jsonNumber(row, "gt_pixels", "lasting_within_range");
    EXPECT_EQ(lasting + jsonNumber(row, "gt_pixels", "transient_within_range"),
              jsonNumber(row, "gt_pixels", "within_range"))
        << source;
  }
  EXPECT_GT(jsonNumber(mesh_row, "gt_pixels", "transient_within_range"), 0.0);
  EXPECT_LT(jsonNumber(rowOf(json, "fused"), "d1_all", "transient_within_range"),
            jsonNumber(mesh_row, "d1_all", "transient_within_range"));
  EXPECT_LT(jsonNumber(mesh_row, "d1_all", "lasting_within_range"), jsonNumber(mesh_row, "d1_all", "within_range"));
  EXPECT_NE(readFile(out.file("report.md")).find("| source | lasting pixels |"), std::string::npos);
  for (const char* file : {"mesh.ply", "mesh_lidar.ply", "mesh_stereo.ply", "config.yaml", "report.md"})
    EXPECT_TRUE(msf::test::fileExists(out.file(file))) << file;
  EXPECT_NE(readFile(out.file("report.md")).find("evaluation protocol 4"), std::string::npos);
  EXPECT_NE(r.out.find("mesh_stereo"), std::string::npos) << r.out; // the console's table
  // The configuration in full, in summary.json and beside it.
  EXPECT_NE(json.find("\"rings\": {\"modulo\": 4, \"heldout_remainder\": 2}"), std::string::npos);
  EXPECT_EQ(jsonNumber(json, "max_depth_m", "tsdf_integrator"), 40);
  EXPECT_NE(readFile(out.file("config.yaml")).find("heldout_remainder: 2"), std::string::npos);
}

TEST_F(PipelineTest, SyntheticHoldoutScoresMovingCarsApartAndSplitsTheRestByTheScans) {
  // Under -holdout the street's held-out rings are the truth; its moving cars are still scored
  // apart, and the scans split the static pixels in range: few of them transient.
  msf::test::TempDir out;
  const std::string json = reconstruct(dataset(), "-frames 0:2 -holdout", out).summary;
  ASSERT_FALSE(json.empty());
  EXPECT_NE(json.find("\"moving_split\": true"), std::string::npos);
  EXPECT_NE(json.find("\"transient_split\": true"), std::string::npos);
  const std::string mesh = rowOf(json, "mesh");
  const double in_range = jsonNumber(mesh, "gt_pixels", "within_range");
  EXPECT_GT(jsonNumber(mesh, "gt_pixels", "moving_all"), 100.0);
  const double transient = jsonNumber(mesh, "gt_pixels", "transient_within_range");
  EXPECT_EQ(jsonNumber(mesh, "gt_pixels", "lasting_within_range") + transient, in_range);
  EXPECT_LT(transient, 0.02 * in_range);
}

TEST_F(PipelineTest, SyntheticGroundTruthScoresStaticAndMovingPixelsApart) {
  // The default street has moving cars: their pixels (gt/moving_0) are scored apart, and the
  // ghost figure counts the mesh's vertices where a car was (gt/moving_objects.txt).
  const msf::synthetic::GroundTruth truth(dataset());
  ASSERT_TRUE(truth.hasMovingMasks());
  std::size_t expected_moving = 0, expected_all = 0;
  for (std::size_t i = 0; i < 2; ++i) {
    const cv::Mat depth = truth.depth(i), mask = truth.movingMask(i);
    expected_all += static_cast<std::size_t>(cv::countNonZero(depth > 0.f));
    expected_moving += static_cast<std::size_t>(cv::countNonZero((depth > 0.f) & (mask > 0)));
  }
  ASSERT_GT(expected_moving, 100u) << "the street's first frames show no moving car";
  msf::test::TempDir out;
  const auto [r, json] = reconstruct(dataset(), "-frames 0:1", out);
  ASSERT_FALSE(json.empty());
  EXPECT_NE(json.find("\"moving_split\": true"), std::string::npos);
  EXPECT_NE(json.find("\"no_ghosts\": null"), std::string::npos);
  const std::string mesh = rowOf(json, "mesh"), fused = rowOf(json, "fused");
  ASSERT_FALSE(mesh.empty()) << json;
  const double pixels = jsonNumber(json, "gt_pixels", "reconstruction_evaluation");
  const double static_pixels = jsonNumber(mesh, "gt_pixels", "all");
  const double moving_pixels = jsonNumber(mesh, "gt_pixels", "moving_all");
  EXPECT_EQ(pixels, static_cast<double>(expected_all));
  EXPECT_EQ(moving_pixels, static_cast<double>(expected_moving));
  EXPECT_EQ(static_pixels + moving_pixels, pixels);
  EXPECT_EQ(jsonNumber(fused, "gt_pixels", "moving_all"), moving_pixels);
  EXPECT_GT(jsonNumber(mesh, "completeness", "accuracy"), 0.3); // the mesh's own accuracy row
  // Its weight curve starts with the whole mesh, and a higher bar keeps less of it.
  EXPECT_EQ(jsonNumber(mesh, "min_weight", "by_min_weight"), 0.0);
  EXPECT_EQ(jsonNumber(mesh, "accuracy_mean_m", "by_min_weight"), jsonNumber(mesh, "accuracy_mean_m", "accuracy"));
  EXPECT_EQ(jsonNumber(mesh, "completeness", "by_min_weight"), jsonNumber(mesh, "completeness", "accuracy"));
  const std::size_t top_bar = mesh.find("\"min_weight\": 1000");
  ASSERT_NE(top_bar, std::string::npos) << mesh;
  EXPECT_LT(jsonNumber(mesh.substr(top_bar), "completeness"), jsonNumber(mesh, "completeness", "accuracy"));
  // Two frames: where the cars were at the first and no longer are at the last are ghosts.
  const double ghosts = jsonNumber(mesh, "share", "ghosts");
  EXPECT_GT(ghosts, 0.0);
  EXPECT_LT(ghosts, 0.05);
  EXPECT_GT(jsonNumber(mesh, "vertices", "ghosts"), 1000.0);
  // Crumbs and specks are small pieces, which are pieces.
  const double small_pieces = jsonNumber(mesh, "small_pieces", "crumbs");
  EXPECT_LE(jsonNumber(mesh, "crumbs", "crumbs") + jsonNumber(mesh, "specks", "crumbs"), small_pieces);
  EXPECT_LE(small_pieces, jsonNumber(mesh, "pieces", "crumbs"));
  EXPECT_EQ(jsonNumber(mesh, "max_triangles", "crumbs"), 50);
  // The crumbs by the frames since their place was left (1, 2, 3 or more) add up to them.
  const std::size_t ages = mesh.find("\"by_frames_since_left\": [");
  ASSERT_NE(ages, std::string::npos) << mesh;
  std::istringstream counts(mesh.substr(mesh.find('[', ages) + 1));
  double by_age = 0, count = 0;
  int buckets = 0;
  for (char separator = ','; separator == ',' && counts >> count >> separator; ++buckets)
    by_age += count;
  EXPECT_EQ(buckets, 3);
  EXPECT_EQ(by_age, jsonNumber(mesh, "crumbs", "crumbs"));
  EXPECT_NE(readFile(out.file("report.md")).find("| ghosts | crumbs | specks |"), std::string::npos);
  EXPECT_NE(readFile(out.file("report.md")).find("source (moving objects)"), std::string::npos);
  // The console gives the true sky the mesh covers beside the image mask's open sky.
  char true_sky[96];
  std::snprintf(true_sky, sizeof(true_sky), "true sky covered by mesh        %.2f %% of %.0f pixels",
                100 * jsonNumber(mesh, "share", "true_sky"), jsonNumber(mesh, "sky_pixels", "true_sky"));
  EXPECT_GT(jsonNumber(mesh, "sky_pixels", "true_sky"), 10000.0);
  EXPECT_NE(r.out.find(true_sky), std::string::npos) << true_sky << "\n" << r.out;
  EXPECT_NE(r.out.find("open sky covered by mesh"), std::string::npos) << r.out;
  // Split by the class of the nearest true surface (gt/scene_classes.txt): the parts add up
  // to the mean (each rounded to 4 digits), and the road is there, meshed nearly whole.
  const std::size_t classes = mesh.find("\"by_class\": [");
  ASSERT_NE(classes, std::string::npos) << mesh;
  const std::string split = mesh.substr(classes, mesh.find(']', classes) - classes);
  double parts = 0;
  for (std::size_t at = split.find("\"contribution_m\""); at != std::string::npos;
       at = split.find("\"contribution_m\"", at + 1))
    parts += jsonNumber(split.substr(at), "contribution_m");
  EXPECT_NEAR(parts, jsonNumber(mesh, "accuracy_mean_m", "accuracy"), 5e-4);
  const std::string ground = split.substr(split.find("\"class\": \"ground\""));
  EXPECT_GT(jsonNumber(ground, "vertices"), 1000.0);
  EXPECT_GT(jsonNumber(ground, "completeness"), 0.9);
  EXPECT_NE(split.find("\"class\": \"off_surface\""), std::string::npos) << split; // the cars' ghosts
  EXPECT_NE(readFile(out.file("report.md")).find("By the class of the nearest true surface"), std::string::npos);
}

TEST_F(PipelineTest, SyntheticCarsWhereTheLastFrameSawThemAreNoGhosts) {
  // One frame: every car in the mesh is where the run's last frame saw it, a true surface off
  // the static one (gt/scene.ply leaves the cars out): no ghost, no crumb of one.
  msf::test::TempDir out;
  const std::string json = reconstruct(dataset(), "-frames 0:0", out).summary;
  ASSERT_FALSE(json.empty());
  const std::string mesh = rowOf(json, "mesh");
  ASSERT_FALSE(mesh.empty()) << json;
  EXPECT_EQ(jsonNumber(mesh, "ghost_vertices", "ghosts"), 0.0);
  EXPECT_EQ(jsonNumber(mesh, "crumbs", "crumbs"), 0.0);
  const std::string split = mesh.substr(mesh.find("\"by_class\": ["));
  const std::string cars = split.substr(split.find("\"class\": \"off_surface\""));
  EXPECT_GT(jsonNumber(cars, "vertices"), 100.0) << "the first frame's cars are not in the mesh";
}

TEST_F(PipelineTest, ComparePaperScoresThePaperAsPublishedBesideOurs) {
  // -compare_paper runs config/paper.yaml on the same frames at the same poses into a map of its
  // own: its per-frame depth ("paper") and its mesh ("mesh_paper") are scored as ours are.
  msf::test::TempDir out;
  const auto [r, json] = reconstruct(dataset(), "-frames 0:1 -compare_paper", out);
  ASSERT_FALSE(json.empty());
  EXPECT_TRUE(msf::test::fileExists(out.file("mesh_paper.ply")));

  // The per-frame depth against the synthetic ground truth: the paper's row beside ours.
  const std::size_t depth_at = json.find("\"depth\": {"), depth_end = json.find("\"mesh_accuracy\"");
  ASSERT_NE(depth_at, std::string::npos) << json;
  const std::string depth = json.substr(depth_at, depth_end - depth_at);
  ASSERT_NE(depth.find("\"paper\": {"), std::string::npos) << depth;
  const double pixels = jsonNumber(depth, "gt_pixels", "fused");
  EXPECT_GT(pixels, 10000);
  EXPECT_EQ(jsonNumber(depth, "gt_pixels", "paper"), pixels); // the same pixels
  const double paper_coverage = jsonNumber(depth, "coverage", "paper");
  const double paper_d1 = jsonNumber(depth, "d1_all", "paper"), ours_d1 = jsonNumber(depth, "d1_all", "fused");
  EXPECT_GT(paper_coverage, 0.8); // steps 1-4 fill most of the image, as ours (0.916 and 0.920 when written)
  EXPECT_LE(paper_coverage, 1.0);
  EXPECT_GT(paper_d1, 0.0);
  EXPECT_LT(paper_d1, 0.5);
  EXPECT_GT(paper_d1, ours_d1); // what our additions add (docs/paper.md; 19.5 against 11.8 % when written)
  const double paper_mae = jsonNumber(depth, "mae_m", "paper");
  EXPECT_GT(paper_mae, 0.0);
  EXPECT_LT(paper_mae, 10.0);

  // Protocol 4: the paper's map and depth, rendered and scored at the same pixels as ours.
  const double gt_pixels = jsonNumber(json, "gt_pixels", "reconstruction_evaluation");
  for (const char* source : {"mesh", "fused", "mesh_paper", "paper"}) {
    const std::string row = rowOf(json, source);
    ASSERT_FALSE(row.empty()) << source << " row missing:\n" << json;
    EXPECT_EQ(jsonNumber(row, "gt_pixels", "all") + jsonNumber(row, "gt_pixels", "moving_all"), gt_pixels) << source;
    const double coverage = jsonNumber(row, "coverage", "within_range"), d1 = jsonNumber(row, "d1_all", "within_range");
    EXPECT_GT(coverage, 0.05) << source;
    EXPECT_LE(coverage, 1.0) << source;
    EXPECT_GE(d1, 0.0) << source;
    EXPECT_LE(d1, 1.0) << source;
    EXPECT_GE(jsonNumber(row, "mae_m", "within_range"), 0.0) << source;
  }
  EXPECT_GT(jsonNumber(rowOf(json, "mesh_paper"), "completeness", "accuracy"), 0.0); // scored against gt/scene.ply
  // Our mesh kept at the highest bar on its weights that is as complete as the paper's mesh.
  const std::string mesh = rowOf(json, "mesh");
  const double paper_completeness = jsonNumber(rowOf(json, "mesh_paper"), "completeness", "accuracy");
  EXPECT_GE(jsonNumber(mesh, "completeness", "at_completeness_of"), paper_completeness);
  EXPECT_LE(jsonNumber(mesh, "completeness", "at_completeness_of"), jsonNumber(mesh, "completeness", "accuracy"));
  EXPECT_GT(jsonNumber(mesh, "min_weight", "at_completeness_of"), 0.0);
  const std::string report = readFile(out.file("report.md"));
  for (const char* row : {"| paper |", "| mesh_paper |", "the paper as published (config/paper.yaml",
                          "at the completeness of each other mesh", "| bar | vertices | accuracy m | completeness |"})
    EXPECT_NE(report.find(row), std::string::npos) << row << " not in report.md:\n" << report;
  EXPECT_NE(r.out.find("mesh_paper"), std::string::npos) << r.out; // the console's table
  EXPECT_NE(r.out.find("mesh as complete as mesh_paper"), std::string::npos) << r.out;
}

TEST_F(PipelineTest, GarbledSceneClassesAreAClearErrorAndLeaveNoOutput) {
  // The street with its gt/scene_classes.txt replaced: one run past the mesh's vertices.
  msf::test::TempDir dir;
  const fs::path copy = dir.file("street"), source = dataset();
  fs::create_directories(copy / "gt");
  for (const char* entry : {"sequences", "poses"})
    fs::create_symlink(source / entry, copy / entry);
  for (const auto& e : fs::directory_iterator(source / "gt"))
    if (e.path().filename() != "scene_classes.txt")
      fs::create_symlink(e.path(), copy / "gt" / e.path().filename());
  std::ofstream(copy / "gt" / "scene_classes.txt") << "# garbled\n0 3 ground\n3 999999999 tree\n";
  const std::string out = dir.file("out");
  const auto r = msf::test::runTool("msf_reconstruct", copy.string() + " -frames 0:0 -panels 0 -o " + out);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_reconstruct: error: surface classes '" + (copy / "gt" / "scene_classes.txt").string() +
                       "' line 3: the run of 999999999 vertices from 3 goes past the mesh's"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out)) << "a failed run left " << out;
}

TEST(ReconstructEvaluation, BadInputIsAClearErrorAndLeavesNoOutput) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  auto fails = [&](const std::string& dataset, const std::string& options, const std::string& message) {
    const std::string out = dir.file("out");
    const auto r = msf::test::runTool("msf_reconstruct", dataset + " -frames 0:1 -panels 0 -o " + out + " " + options);
    EXPECT_NE(r.exit_code, 0) << options;
    EXPECT_NE(r.err.find("msf_reconstruct: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << "a failed run left " << out;
  };
  const std::string without_poses = kittiCopy(dir.file("no_poses"), false, false);
  // Without poses the default is to estimate them (test_odometry_tools.cpp); asking for the
  // dataset's is an error.
  fails(without_poses, "-holdout -poses dataset", "has no poses");
  const std::string no_rings = kittiCopy(dir.file("no_rings"), true, true);
  fails(no_rings, "-holdout", "000000.bin' has 1 ring id(s) and none is held out");
  const std::string kitti = msf::test::kittiDir() + "/odometry/sequences/04";
  fails(kitti, "-compare_sources garbage", "got '" + kitti + "' and 'garbage' too");
  fails(kitti, "-compare_sources=lidar", "-compare_sources=lidar");
  std::ofstream(dir.file("rings.yaml")) << "%YAML:1.0\nrings:\n  modulo: 1\n";
  fails(kitti, "-holdout -config " + dir.file("rings.yaml"), "rings.modulo");
  // Without -holdout the sorted scans are only scans: the map is made.
  const auto r = msf::test::runTool("msf_reconstruct", no_rings + " -frames 0:0 -panels 0 -o " + dir.file("ok"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}
