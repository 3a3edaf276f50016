// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// A rig unlike KITTI's (640x480 cameras of f 500 px, a 0.12 m baseline, a 32-beam LiDAR):
// the keys that follow from it, its synthetic street, and the street reconstructed end to end.
#include <msf/fusion/point_types.h>
#include <msf/io/cloud_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/rig_file.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/rig_adaptation.h>
#include <msf/range_image/ring_split.h>
#include <msf/synthetic/synthetic_generator.h>
#include <msf/synthetic/synthetic_rig.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using msf::synthetic::SyntheticConfig;

SyntheticConfig compactRig() {
  SyntheticConfig c;
  c.camera = "pinhole";
  c.lidar_model = "hdl32e";
  return c;
}

/// The compact rig's street of `frames` frames, written into `dir`'s street/.
msf::Sequence compactStreet(const msf::test::TempDir& dir, int frames) {
  SyntheticConfig config = compactRig();
  config.frames = frames;
  msf::synthetic::SyntheticGenerator(config).writeDataset(dir.file("street"));
  return msf::Sequence(dir.file("street"));
}

std::string printed(const msf::PipelineConfig& config) {
  std::ostringstream out;
  config.print(out);
  return out.str();
}

struct MeshFigures {
  double range_m, accuracy_m, completeness, ghosts;
};

/// msf_reconstruct on `dataset` with `options`: the mesh's figures from summary.json.
MeshFigures reconstruct(const std::string& dataset, const std::string& options) {
  msf::test::TempDir out;
  const auto r = msf::test::runTool("msf_reconstruct", dataset + " -panels 0 " + options + " -o " + out.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const std::string json = readFile(out.file("summary.json"));
  return {jsonNumber(json, "range_m"), jsonNumber(json, "accuracy_mean_m", "mesh_accuracy"),
          jsonNumber(json, "completeness", "mesh_accuracy"), jsonNumber(json, "share", "ghosts")};
}

/// Frame `i` of `sequence` through msf_interpolate, msf_stereo -prior and msf_fuse -left with -rig
/// `rig` (and `options` on each): the fused depth.
cv::Mat fusedByTheTools(const msf::Sequence& sequence, std::size_t i, const std::string& rig, const std::string& options) {
  msf::test::TempDir out;
  const std::string with_rig = " -rig " + rig + options;
  const std::string steps[][2] = {
      {"msf_interpolate", sequence.scanPath(i) + " " + out.file("lidar.pcd") + with_rig},
      {"msf_stereo", sequence.imagePath(0, i) + " " + sequence.imagePath(1, i) + " " + out.file("stereo.pcd") +
                         with_rig + " -color " + sequence.imagePath(2, i) + " -prior " + out.file("lidar.pcd")},
      {"msf_fuse", out.file("lidar.pcd") + " " + out.file("stereo.pcd") + " " + out.file("fused.pcd") + with_rig +
                       " -left " + sequence.imagePath(0, i) + " -color " + sequence.imagePath(2, i)},
  };
  for (const auto& step : steps) {
    const auto r = msf::test::runTool(step[0], step[1]);
    EXPECT_EQ(r.exit_code, 0) << step[0] << ": " << r.err;
  }
  pcl::PointCloud<msf::PointXYZRGBWeight> fused;
  msf::loadCloud(out.file("fused.pcd"), fused);
  return msf::cloudToDepthImage(fused);
}

} // namespace

TEST(AnyRig, KittisCalibrationsKeepEveryKey) {
  MSF_REQUIRE_KITTI();
  const msf::PipelineConfig config;
  const msf::Calibration rigs[] = {
      msf::loadCalibration(msf::test::kittiDir() + "/odometry/sequences/04/calib.txt"),
      msf::synthetic::syntheticRig(SyntheticConfig())}; // the default street's, with its 64 beams
  for (const msf::Calibration& rig : rigs) {
    msf::RigAdaptation derived;
    EXPECT_EQ(printed(msf::adaptToRig(config, rig, &derived)), printed(config)) << rig.source;
    EXPECT_EQ(derived.max_depth_m, 40.0) << rig.source;
    EXPECT_GT(derived.stereo_trusted_depth_m, 47.0) << rig.source; // f·B 380-388 px·m over 8 px
    EXPECT_NEAR(derived.ring_scale, 1.0, 1e-12) << rig.source;
  }
}

TEST(AnyRig, TheCompactRigsKeysFollowItsBaselineAndBeams) {
  const msf::Calibration rig = msf::synthetic::syntheticRig(compactRig());
  msf::RigAdaptation derived;
  const msf::PipelineConfig kitti, c = msf::adaptToRig(kitti, rig, &derived);
  EXPECT_DOUBLE_EQ(derived.geometry.focal_baseline, 60.0);
  EXPECT_DOUBLE_EQ(derived.max_depth_m, 7.5); // 60 px·m over 8 px
  EXPECT_DOUBLE_EQ(c.integrator.max_depth_m, 7.5);
  // 500 px times 41.34 degrees over 31 spacings, against 721.5377 px times 26.9 over 63.
  EXPECT_NEAR(derived.ring_scale, 500.0 * 41.34 / 31 / (721.5377 * 26.9 / 63), 1e-9);
  EXPECT_EQ(c.fusion.edge_window_rows, 29); // 13 x 2.164 = 28.1, kept odd
  EXPECT_EQ(c.fusion.parallax_max_rows, 35);
  EXPECT_EQ(c.stereo.guidance_bridge_rows, 104);
  EXPECT_EQ(c.interpolation.slice.short_gap_px, 9);
  EXPECT_EQ(c.interpolation.slice.max_gap_px, 139); // 64 x 2.165 = 138.5
  // Turned off, the rig changes nothing.
  msf::PipelineConfig as_written = kitti;
  as_written.rig.scale_ring_rows = false;
  as_written.rig.stereo_min_disparity_px = 0.0;
  EXPECT_EQ(printed(msf::adaptToRig(as_written, rig)), printed(as_written));
}

TEST(AnyRig, ARigFileGivesTheSyntheticRigItsCamerasAndBeams) {
  msf::test::TempDir dir;
  std::ofstream(dir.file("rig.yaml")) << "image_width: 800\nimage_height: 600\n"
                                         "left: {fx: 600.0, fy: 600.0, cx: 401.5, cy: 299.0}\nbaseline_m: 0.2\n"
                                         "lidar:\n  T_cam_lidar: [0, -1, 0, 0,  0, 0, -1, -0.08,  1, 0, 0, -0.27,  0, 0, 0, 1]\n"
                                         "  beam_elevations_deg: [-15, -13, -11, -9, -7, -5, -3, -1, 1, 3, 5, 7, 9, 11, 13, 15]\n";
  SyntheticConfig config;
  msf::synthetic::applyRig(msf::loadRigFile(dir.file("rig.yaml")), config);
  const msf::Calibration rig = msf::synthetic::syntheticRig(config);
  EXPECT_EQ(rig.image_size, cv::Size(800, 600));
  EXPECT_DOUBLE_EQ(rig.fx(), 600.0);
  EXPECT_DOUBLE_EQ(rig.cx(), 401.5);
  EXPECT_DOUBLE_EQ(rig.focalBaseline(), 120.0);
  EXPECT_EQ(rig.lidar.rings, 16);
  EXPECT_DOUBLE_EQ(rig.lidar.beam_elevations_deg.front(), -15.0);
  // rings without their elevations cannot be simulated: said so, naming the key
  std::ofstream(dir.file("rings.yaml")) << "image_width: 640\nimage_height: 480\nleft: {fx: 500.0, fy: 500.0, cx: 320.0, "
                                           "cy: 240.0}\nbaseline_m: 0.12\nlidar:\n  T_cam_lidar: [1, 0, 0, 0,  0, 1, 0, 0,  "
                                           "0, 0, 1, 0,  0, 0, 0, 1]\n  rings: 32\n";
  EXPECT_NE(msf::test::errorOf([&] { msf::synthetic::applyRig(msf::loadRigFile(dir.file("rings.yaml")), config); })
                .find("lidar.rings 32 without lidar.beam_elevations_deg"),
            std::string::npos);
}

TEST(AnyRig, TheSimulatedHdl32eSweepsOneRingABeam) {
  SyntheticConfig config = compactRig();
  config.frames = 1;
  const msf::synthetic::SyntheticGenerator generator(config);
  EXPECT_EQ(generator.lidar().ringCount(), 32);
  EXPECT_DOUBLE_EQ(generator.lidar().elevationsDeg().front(), 10.67);
  EXPECT_DOUBLE_EQ(generator.lidar().elevationsDeg().back(), -30.67);
  const msf::synthetic::SyntheticFrame frame = generator.renderFrame(0, false);
  EXPECT_EQ(frame.images[0].size(), cv::Size(640, 480));
  EXPECT_EQ(msf::ringIds(frame.scan).back() + 1, 32); // protocol 2's ring ids from the order
}

TEST(AnyRig, TheCompactRigsStreetReconstructsWithinItsTargets) {
  // A short drive behind a moving car (the oncoming ones, which pass in the first second, need a
  // longer drive to be seen gone): scored within the range the rig resolves (f·B / 8 px = 7.5 m),
  // the map is accurate, complete and free of ghosts; run with KITTI's sizes (far stereo to 40 m,
  // KITTI's windows), the same street is far from complete and less accurate.
  msf::test::TempDir dir;
  SyntheticConfig config = compactRig();
  config.frames = 8;
  config.moving_cars_oncoming = 0;
  msf::synthetic::SyntheticGenerator(config).writeDataset(dir.file("street"));
  const MeshFigures rig = reconstruct(dir.file("street"), "");
  EXPECT_DOUBLE_EQ(rig.range_m, 7.5);
  EXPECT_LE(rig.accuracy_m, 0.08);
  EXPECT_GE(rig.completeness, 0.95);
  EXPECT_LT(rig.ghosts, 0.01);
  std::ofstream(dir.file("as_kitti.yaml")) << "%YAML:1.0\nrig:\n  stereo_min_disparity_px: 0.0\n  scale_ring_rows: false\n";
  const MeshFigures as_kitti = reconstruct(dir.file("street"), "-config " + dir.file("as_kitti.yaml"));
  EXPECT_DOUBLE_EQ(as_kitti.range_m, 40.0);
  EXPECT_LT(as_kitti.completeness, 0.9);
  EXPECT_GT(as_kitti.accuracy_m, 2.0 * rig.accuracy_m);
}

TEST(AnyRig, TheToolsOfOneStageFollowTheRigAsTheEngineDoes) {
  // The compact rig's frame through the tools, each given the rig file: the engine's fused depth,
  // pixel for pixel. With the keys as written (KITTI's rows between rings) it is another depth.
  msf::test::TempDir dir;
  const msf::Sequence sequence = compactStreet(dir, 2);
  const std::string rig = sequence.directory() + "/rig.yaml";
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{});
  const cv::Mat expected = engine.addFrame(sequence.load(1)).fused.depth; // holes filled, as msf_fuse's
  EXPECT_GT(cv::countNonZero(expected), expected.total() / 2);

  const cv::Mat chained = fusedByTheTools(sequence, 1, rig, "");
  ASSERT_EQ(chained.size(), expected.size());
  EXPECT_EQ(cv::norm(expected, chained, cv::NORM_INF), 0.0) << "the tools' fused depth differs from the engine's";

  // The sequence's folder given as the calibration: its rig file, read before its calib.txt (which
  // lists no beams), as the dataset readers read it.
  const cv::Mat from_folder = fusedByTheTools(sequence, 1, sequence.directory(), "");
  EXPECT_EQ(cv::norm(expected, from_folder, cv::NORM_INF), 0.0) << "-calib DIR did not read DIR/rig.yaml";

  std::ofstream(dir.file("as_written.yaml")) << "%YAML:1.0\nrig:\n  scale_ring_rows: false\n";
  const cv::Mat as_written = fusedByTheTools(sequence, 1, rig, " -config " + dir.file("as_written.yaml"));
  EXPECT_GT(cv::norm(expected, as_written, cv::NORM_INF), 0.0);
}

TEST(AnyRig, ACloudOfAnotherRigOfTheSameSizeIsRefused) {
  // The compact rig's clouds given with a rig of the same image size but a 4 % longer focal length:
  // fused or integrated at other rays without a word before; refused, naming both cameras.
  msf::test::TempDir dir;
  const msf::Sequence sequence = compactStreet(dir, 1);
  const std::string rig = sequence.directory() + "/rig.yaml";
  msf::Calibration other = sequence.calibration();
  for (int camera = 0; camera < 4; ++camera)
    other.P[camera](0, 0) *= 1.04;
  msf::saveRigFile(other, dir.file("other.yaml"));
  const auto run = [&](const std::string& tool, const std::string& arguments) {
    return msf::test::runTool(tool, arguments);
  };
  ASSERT_EQ(run("msf_interpolate", sequence.scanPath(0) + " " + dir.file("lidar.pcd") + " -rig " + rig).exit_code, 0);
  ASSERT_EQ(run("msf_stereo", sequence.imagePath(0, 0) + " " + sequence.imagePath(1, 0) + " " + dir.file("stereo.pcd") +
                                  " -rig " + rig + " -prior " + dir.file("lidar.pcd"))
                .exit_code,
            0);
  const std::string fuse = dir.file("lidar.pcd") + " " + dir.file("stereo.pcd") + " ";
  const auto refused = run("msf_fuse", fuse + dir.file("other.pcd") + " -rig " + dir.file("other.yaml"));
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("DepthFusion: the stereo cloud was made by a camera of fx 500.00, fy 500.00, cx 320.00, "
                             "cy 240.00, not by the left camera of calibration '" +
                             dir.file("other.yaml") + "' (fx 520.00"),
            std::string::npos)
      << refused.err;
  EXPECT_FALSE(fs::exists(dir.file("other.pcd")));
  ASSERT_EQ(run("msf_fuse", fuse + dir.file("fused.pcd") + " -rig " + rig).exit_code, 0);
  std::ofstream(dir.file("poses.txt")) << "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const std::string integrate = dir.file("fused.pcd") + " -poses " + dir.file("poses.txt") + " -o ";
  const auto integrated =
      run("msf_integrate", integrate + dir.file("other_volume.pcd") + " -rig " + dir.file("other.yaml"));
  EXPECT_EQ(integrated.exit_code, 1);
  EXPECT_NE(integrated.err.find("fused.pcd' was made by a camera of fx 500.00"), std::string::npos) << integrated.err;
  EXPECT_FALSE(fs::exists(dir.file("other_volume.pcd")));
  EXPECT_EQ(run("msf_integrate", integrate + dir.file("volume.pcd") + " -rig " + rig).exit_code, 0);
}

TEST(AnyRig, MsfEvalMeshScoresTheRigsRangeAsMsfReconstructDoes) {
  // One yardstick: the compact rig's map scored by msf_eval_mesh within the range msf_reconstruct
  // scores it to (f·B / 8 px = 7.5 m), not KITTI's 40 m, where the rig's frames see little.
  msf::test::TempDir dir;
  compactStreet(dir, 3);
  auto r = msf::test::runTool("msf_reconstruct", dir.file("street") + " -panels 0 -o " + dir.file("out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = msf::test::runTool("msf_eval_mesh", dir.file("out/mesh.ply") + " " + dir.file("street") + " -o " +
                                              dir.file("eval.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double reconstruct = jsonNumber(readFile(dir.file("out/summary.json")), "completeness", "mesh_accuracy");
  const double evaluated = jsonNumber(readFile(dir.file("eval.json")), "completeness");
  EXPECT_GT(reconstruct, 0.9);
  EXPECT_NEAR(evaluated, reconstruct, 1e-4);
}
