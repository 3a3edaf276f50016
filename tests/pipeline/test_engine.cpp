// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The engine as a library object: fed frame by frame it gives msf_reconstruct's map, byte for
// byte; its thread budget changes nothing but the time.
#include <msf/io/cloud_io.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/reconstructor.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

namespace {

namespace fs = std::filesystem;

/// The mesh and volume files of `engine`'s map, written as msf_reconstruct writes them.
std::pair<std::string, std::string> savedMap(msf::Reconstructor& engine, const msf::test::TempDir& dir) {
  pcl::PolygonMesh polygons;
  engine.mesh().toPolygonMesh(polygons);
  msf::saveMesh(dir.file("mesh.ply"), polygons);
  engine.volume().save(dir.file("volume.pcd"));
  return {readFile(dir.file("mesh.ply")), readFile(dir.file("volume.pcd"))};
}

/// Frames 0-2 of the test street fed one call each into `engine`.
void feed(msf::Reconstructor& engine, const msf::Sequence& sequence) {
  for (std::size_t i = 0; i < 3; ++i) {
    const msf::FrameResult r = engine.addFrame(sequence.load(i));
    EXPECT_TRUE(r.has_pose);
    EXPECT_EQ(r.fused.depth.size(), sequence.calibration().image_size);
    EXPECT_EQ(r.fused.weight.size(), sequence.calibration().image_size);
  }
}

} // namespace

TEST_F(PipelineTest, TheEngineFedFrameByFrameGivesTheToolsMapByteForByte) {
  msf::test::TempDir dir;
  const auto r = msf::test::runTool("msf_reconstruct", dataset() + " -frames 0:2 -panels 0 -o " + dir.file("out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const msf::Sequence sequence(dataset());
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{});
  feed(engine, sequence);
  msf::test::TempDir mine;
  const auto [mesh, volume] = savedMap(engine, mine);
  EXPECT_TRUE(mesh == readFile(dir.file("out/mesh.ply"))) << "the mesh differs from msf_reconstruct's";
  EXPECT_TRUE(volume == readFile(dir.file("out/volume.pcd"))) << "the volume differs from msf_reconstruct's";
}

TEST_F(PipelineTest, WithEarlierScansTheEngineFedFrameByFrameGivesTheToolsMap) {
  msf::test::TempDir dir;
  const std::string config_path = dir.file("earlier.yaml");
  std::ofstream(config_path) << "accumulation:\n  scans: 2\n";
  const auto r = msf::test::runTool("msf_reconstruct", dataset() + " -frames 0:2 -panels 0 -config " + config_path +
                                                           " -o " + dir.file("out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const msf::Sequence sequence(dataset());
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig::load(config_path));
  feed(engine, sequence);
  msf::test::TempDir mine;
  const auto [mesh, volume] = savedMap(engine, mine);
  EXPECT_TRUE(mesh == readFile(dir.file("out/mesh.ply"))) << "the mesh differs from msf_reconstruct's";
  EXPECT_TRUE(volume == readFile(dir.file("out/volume.pcd"))) << "the volume differs from msf_reconstruct's";
  msf::Reconstructor own_scans(sequence.calibration(), msf::PipelineConfig{});
  feed(own_scans, sequence);
  msf::test::TempDir other;
  EXPECT_FALSE(savedMap(own_scans, other).second == volume) << "the earlier scans changed nothing";
}

TEST_F(PipelineTest, AFrameThatDoesNotFitIsRefusedBeforeTheEngineChanges) {
  const msf::Sequence sequence(dataset());
  msf::Reconstructor::Options odometry;
  odometry.poses = msf::Reconstructor::PoseMode::Odometry;
  msf::Reconstructor clean(sequence.calibration(), msf::PipelineConfig{}, odometry);
  const msf::Frame first = sequence.load(0), second = sequence.load(1);
  clean.addFrame(first);
  const Eigen::Isometry3d pose = clean.addFrame(second).T_world_cam0;

  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{}, odometry);
  const auto refused = [&](msf::Frame frame, const std::string& message) {
    const std::string error = msf::test::errorOf([&] { engine.addFrame(frame); });
    EXPECT_NE(error.find(message), std::string::npos) << error;
  };
  msf::Frame broken = first;
  broken.scan.reset();
  refused(broken, "frame 0 has no scan: the engine needs the LiDAR's points each frame");
  msf::Reconstructor given(sequence.calibration(), msf::PipelineConfig{}); // its pose used: no tracking
  EXPECT_NE(msf::test::errorOf([&] { given.addFrame(broken); }).find("frame 0 has no scan"), std::string::npos);
  EXPECT_NE(msf::test::errorOf([&] { given.computeDepth(broken); }).find("frame 0 has no scan"), std::string::npos);
  broken = first; // the scan in millimetres: no return within the LiDAR's range
  broken.scan.reset(new pcl::PointCloud<pcl::PointXYZI>(*first.scan));
  for (auto& p : *broken.scan)
    p.getVector3fMap() *= 1000.f;
  EXPECT_NE(msf::test::errorOf([&] { given.addFrame(broken); })
                .find("frame 0: no return of its scan (" + std::to_string(first.scan->size()) +
                      " points) lands in camera 0"),
            std::string::npos);
  broken = first;
  broken.right = cv::Mat();
  refused(broken, "frame 0's right image is missing or empty");
  broken = first;
  broken.color = cv::Mat(10, 10, CV_8UC3);
  refused(broken, "frame 0's colour image is 10x10 but calibration");
  broken = first; // a BGR pair: the stages need grey
  cv::cvtColor(first.left, broken.left, cv::COLOR_GRAY2BGR);
  refused(broken, "frame 0's left image must be 8-bit grey (CV_8UC1), not CV_8UC3: convert it with cv::cvtColor");
  broken = first;
  broken.color = first.left.clone();
  refused(broken, "frame 0's colour image must be 8-bit BGR (CV_8UC3), not CV_8UC1");
  broken = first;
  broken.point_time_s.assign(3, 0.f);
  refused(broken, "frame 0 has 3 point times for");
  broken = first; // a time the order of frames cannot be told by
  broken.timestamp = std::numeric_limits<double>::quiet_NaN();
  refused(broken, "frame 0's timestamp is nan: seconds from the first frame, or 0 when not known");
  broken = first;
  broken.T_world_cam0.linear() *= 2.0;
  refused(broken, "frame 0's pose T_world_cam0");
  engine.addFrame(first); // the refused frames left no trace: the same poses as a clean engine's
  refused([&] { msf::Frame f = second; f.left = cv::Mat(); return f; }(), "frame 1's left image is missing");
  EXPECT_TRUE(engine.addFrame(second).T_world_cam0.isApprox(pose, 1e-12));
  EXPECT_EQ(engine.odometryMs().size(), 2u);
}

TEST_F(PipelineTest, ARigThatIsNotPhysicalIsRefusedWhenTheEngineIsMade) {
  const msf::Sequence sequence(dataset());
  msf::Calibration rig = sequence.calibration();
  rig.T_cam0_velo.linear() *= 1000.0; // millimetres where metres are due
  EXPECT_NE(msf::test::errorOf([&] { msf::Reconstructor(rig, msf::PipelineConfig{}); })
                .find("the LiDAR-to-camera transform is not a rigid transform"),
            std::string::npos);
  rig = sequence.calibration();
  rig.P[2](0, 0) = -5.0;
  EXPECT_NE(msf::test::errorOf([&] { msf::Reconstructor(rig, msf::PipelineConfig{}); })
                .find("P2 has fx -5"),
            std::string::npos);
}

TEST_F(PipelineTest, TheEngineTakesOneCallAtATime) {
  const msf::Sequence sequence(dataset());
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{});
  std::string other_thread, nested;
  std::size_t meshed = 0;
  engine.run(sequence, {0, 1}, [&](msf::FrameResult&) {
    // While run() holds the engine, another thread's call is refused, not interleaved with it.
    std::thread([&] { other_thread = msf::test::errorOf([&] { engine.mesh(); }); }).join();
    nested = msf::test::errorOf([&] { engine.addFrame(sequence.load(2)); });
    meshed = engine.mesh().triangles.size(); // the callback's own thread may mesh
  });
  for (const auto& [error, expected] :
       {std::pair<std::string, const char*>{other_thread, "msf::Reconstructor::mesh was called while another thread "
                                                          "is in a call of the same engine: it takes one call at a time"},
        {nested, "msf::Reconstructor::addFrame was called within another call of the same engine (run()'s callback): "
                 "only mesh() may be"}})
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  EXPECT_GT(meshed, 0u);
  // Once run() returned, any thread may call it.
  std::size_t after = 0;
  std::thread([&] { after = engine.addFrame(sequence.load(2)).index; }).join();
  EXPECT_EQ(after, 2u);
}

TEST_F(PipelineTest, AnImageThatIsAViewIntoALargerOneGivesItsCopysDepth) {
  // OpenCV's filters read past a view's edge into the image it was cut from.
  const msf::Sequence sequence(dataset());
  const msf::Frame frame = sequence.load(1);
  msf::Frame viewed = frame;
  for (cv::Mat* image : {&viewed.left, &viewed.right, &viewed.color}) {
    cv::Mat larger(image->rows + 40, image->cols + 40, image->type(), cv::Scalar::all(255));
    image->copyTo(larger(cv::Rect(20, 20, image->cols, image->rows)));
    *image = larger(cv::Rect(20, 20, image->cols, image->rows));
  }
  ASSERT_TRUE(viewed.left.isSubmatrix());
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{});
  const msf::FrameResult copied = engine.computeDepth(frame), from_views = engine.computeDepth(viewed);
  EXPECT_EQ(cv::countNonZero(copied.fused.depth != from_views.fused.depth), 0);
  EXPECT_EQ(cv::countNonZero(copied.stereo_depth != from_views.stereo_depth), 0);
}

TEST_F(PipelineTest, AMapTakesAResultOnceAndAnotherMapOfItsRigTakesItToo) {
  // A result integrated twice would weigh double: refused, the map unchanged.
  const msf::Sequence sequence(dataset());
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{});
  msf::FrameResult depth = engine.computeDepth(sequence.load(0));
  engine.integrate(depth);
  msf::test::TempDir once, after;
  const auto map_once = savedMap(engine, once);
  const std::string again = msf::test::errorOf([&] { engine.integrate(depth); });
  msf::FrameResult copy = depth;
  const std::string copied = msf::test::errorOf([&] { engine.integrate(copy); });
  const msf::Frame second = sequence.load(1);
  msf::FrameResult added = engine.addFrame(second);
  const std::string from_add = msf::test::errorOf([&] { engine.integrate(added); });
  for (const std::string& error : {again, copied})
    EXPECT_NE(error.find("frame 0's result is in the map already (addFrame and run integrate theirs): a second "
                         "time would double its weight"),
              std::string::npos)
        << error;
  EXPECT_NE(from_add.find("frame 1's result is in the map already"), std::string::npos) << from_add;
  // The same frame given again in a row, as a loop that feeds one frame twice does.
  const std::string twice = msf::test::errorOf([&] { engine.addFrame(second); });
  EXPECT_NE(twice.find("frame 1 is the frame given last (the same scan): given twice, the map would take it twice"),
            std::string::npos)
      << twice;
  // The map holds frames 0 and 1 once each: as an engine fed them by addFrame.
  msf::Reconstructor fed(sequence.calibration(), msf::PipelineConfig{});
  fed.addFrame(sequence.load(0));
  fed.addFrame(sequence.load(1));
  msf::test::TempDir a, b;
  EXPECT_TRUE(savedMap(engine, a).second == savedMap(fed, b).second) << "a refused result changed the map";
  EXPECT_FALSE(map_once.second == savedMap(engine, after).second);
  // Another map takes the same result; a map of another rig of the same image size does not.
  msf::Reconstructor other(sequence.calibration(), msf::PipelineConfig{});
  EXPECT_NO_THROW(other.integrate(depth));
  msf::Calibration longer = sequence.calibration();
  for (int camera = 0; camera < 4; ++camera)
    longer.P[camera](0, 0) *= 1.04;
  msf::Reconstructor of_another_rig(longer, msf::PipelineConfig{});
  msf::FrameResult next = engine.computeDepth(sequence.load(2));
  EXPECT_NE(msf::test::errorOf([&] { of_another_rig.integrate(next); })
                .find("frame 2's result was computed for a camera of fx 721.54, fy 721.54, cx 609.56, cy 172.85, "
                      "1242x375, not this map's rig (fx 750.40"),
            std::string::npos);
  EXPECT_EQ(of_another_rig.volume().numBlocks(), 0u);
}

TEST_F(PipelineTest, PosesThatAutoModeTrackedInsteadAreSaid) {
  // The first frame has no pose, so every frame is tracked: the later frames' own poses go unused.
  const msf::Sequence sequence(dataset());
  msf::Frame first = sequence.load(0);
  first.has_pose = false;
  msf::Reconstructor automatic(sequence.calibration(), msf::PipelineConfig{});
  automatic.addFrame(first);
  EXPECT_TRUE(automatic.notes().empty());
  automatic.addFrame(sequence.load(1));
  automatic.addFrame(sequence.load(2));
  ASSERT_EQ(automatic.notes().size(), 1u);
  EXPECT_EQ(automatic.notes()[0], "frames with their own pose, from frame 1 on, were tracked by LiDAR odometry "
                                  "instead: the first frame had none, so PoseMode Auto tracks every frame; give the "
                                  "first frame its pose, or use PoseMode Refine to refine the poses with the scans");
  // Asked for, the odometry's poses are no surprise; given, the frames' are used.
  msf::Reconstructor::Options odometry;
  odometry.poses = msf::Reconstructor::PoseMode::Odometry;
  msf::Reconstructor tracked(sequence.calibration(), msf::PipelineConfig{}, odometry);
  msf::Reconstructor given(sequence.calibration(), msf::PipelineConfig{});
  for (std::size_t i = 0; i < 2; ++i) {
    tracked.addFrame(sequence.load(i));
    given.addFrame(sequence.load(i));
  }
  EXPECT_TRUE(tracked.notes().empty());
  EXPECT_TRUE(given.notes().empty());
}

TEST_F(PipelineTest, FramesOutOfTimeOrderAreSaidOnceAndTaken) {
  const msf::Sequence sequence(dataset()); // frames 0.1 s apart
  const std::string said = "frame 1 (at 0.1 s) came after a frame at 0.2 s: the frames are not in time order, which "
                           "the odometry's prediction of each scan's motion and the earlier scans (accumulation) "
                           "assume; give them in the order of Frame::timestamp";
  msf::Reconstructor in_order(sequence.calibration(), msf::PipelineConfig{});
  for (std::size_t i = 0; i < 3; ++i)
    in_order.addFrame(sequence.load(i));
  EXPECT_TRUE(in_order.notes().empty());
  // Given backwards, frame by frame: said once, at the first frame before its predecessor, and
  // every frame taken.
  msf::Reconstructor backwards(sequence.calibration(), msf::PipelineConfig{});
  for (std::size_t i : {2, 1, 0})
    backwards.addFrame(sequence.load(i));
  EXPECT_EQ(backwards.notes(), std::vector<std::string>{said});
  EXPECT_GT(backwards.volume().numBlocks(), 0u);
  // run() over the frames listed backwards says the same.
  msf::Reconstructor run(sequence.calibration(), msf::PipelineConfig{});
  std::size_t results = 0;
  run.run(sequence, {2, 1, 0}, [&](msf::FrameResult&) { ++results; });
  EXPECT_EQ(results, 3u);
  EXPECT_EQ(run.notes(), std::vector<std::string>{said});
  // Frames whose times are not set (all 0) are in no order to check.
  msf::Reconstructor untimed(sequence.calibration(), msf::PipelineConfig{});
  for (std::size_t i : {2, 1}) {
    msf::Frame frame = sequence.load(i);
    frame.timestamp = 0.0;
    untimed.addFrame(frame);
  }
  EXPECT_TRUE(untimed.notes().empty());
}

TEST_F(PipelineTest, TheRigSaysHowItsScansAreTakenToEveryDoor) {
  // The street's scans are taken at one instant: its rig says so, and the engine takes it from
  // the rig whether fed frame by frame or run (the tests above give msf_reconstruct's map). A rig
  // that says its scans sweep carves with a sweep's margin: another map.
  const msf::Sequence sequence(dataset());
  ASSERT_FALSE(sequence.calibration().lidar.sweeping);
  msf::Calibration sweeping = sequence.calibration();
  sweeping.lidar.sweeping = true;
  msf::Reconstructor snapshots(sequence.calibration(), msf::PipelineConfig{});
  msf::Reconstructor swept(sweeping, msf::PipelineConfig{});
  feed(snapshots, sequence);
  feed(swept, sequence);
  msf::test::TempDir a, b;
  EXPECT_FALSE(savedMap(snapshots, a).second == savedMap(swept, b).second)
      << "the rig's lidar.sweeping changed nothing";
}

TEST_F(PipelineTest, AStreetWithoutARigFileIsStillScannedAtOneInstant) {
  // The street as an msf_synth older than rig files wrote it: its ground truth says it is
  // msf_synth's, whose LiDAR takes each scan at one instant. A KITTI sequence without a rig
  // file (no truth) sweeps.
  namespace fs = std::filesystem;
  msf::test::TempDir copy;
  const fs::path sequence = fs::path(copy.path()) / "sequences" / "00";
  fs::create_directories(sequence);
  for (const auto& entry : fs::directory_iterator(fs::path(dataset()) / "sequences" / "00"))
    if (entry.path().filename() != "rig.yaml")
      fs::create_symlink(entry.path(), sequence / entry.path().filename());
  EXPECT_TRUE(msf::Sequence(copy.path()).calibration().lidar.sweeping);
  fs::create_directory_symlink(fs::path(dataset()) / "gt", fs::path(copy.path()) / "gt");
  EXPECT_FALSE(msf::Sequence(copy.path()).calibration().lidar.sweeping);
}

TEST_F(PipelineTest, OneThreadGivesTheSameMapAsAllCores) {
  const msf::Sequence sequence(dataset());
  msf::Reconstructor all(sequence.calibration(), msf::PipelineConfig{});
  msf::Reconstructor::Options single;
  single.threads = 1;
  msf::Reconstructor one(sequence.calibration(), msf::PipelineConfig{}, single);
  feed(all, sequence);
  feed(one, sequence);
  msf::test::TempDir a, b;
  const auto map_all = savedMap(all, a), map_one = savedMap(one, b);
  EXPECT_GT(all.mesh().triangles.size(), 1000u);
  EXPECT_TRUE(map_all.first == map_one.first) << "the mesh depends on the thread budget";
  EXPECT_TRUE(map_all.second == map_one.second) << "the volume depends on the thread budget";
}

TEST_F(PipelineTest, AStreamedEngineWritesItsTilesWhereItIsTold) {
  const msf::Sequence sequence(dataset());
  msf::PipelineConfig config;
  config.streaming.active_radius_m = 101;
  msf::test::TempDir dir;
  msf::Reconstructor::Options options;
  options.stream_directory = dir.path();
  msf::Reconstructor engine(sequence.calibration(), config, options);
  feed(engine, sequence);
  EXPECT_GT(engine.finishStreaming(dir.file("mesh.ply")), 1000u);
  EXPECT_TRUE(fs::is_regular_file(dir.file("tsdf/index.txt")));
  EXPECT_FALSE(fs::is_empty(dir.file("tiles")));
  // Without a folder a streamed map is refused at its first frame, and a folder without streaming at once.
  msf::Reconstructor folderless(sequence.calibration(), config);
  EXPECT_NE(msf::test::errorOf([&] { folderless.addFrame(sequence.load(0)); }).find("stream_directory"),
            std::string::npos);
  EXPECT_NE(msf::test::errorOf([&] { msf::Reconstructor(sequence.calibration(), msf::PipelineConfig{}, options); })
                .find("streaming.active_radius_m is 0"),
            std::string::npos);
}

TEST_F(PipelineTest, TheMapAsAPriorFillsTheFusedDepthsHolesAndLeavesTheMapAsItWas) {
  const msf::Sequence sequence(dataset());
  msf::PipelineConfig without; // the holes the map leaves are the small-hole fill's
  without.fusion.hole_fill_px = 0;
  msf::PipelineConfig with_prior = without;
  with_prior.map_prior.enabled = true;
  msf::Reconstructor plain(sequence.calibration(), without);
  msf::Reconstructor prior(sequence.calibration(), with_prior);
  for (std::size_t i = 0; i < 3; ++i) {
    const msf::FrameResult a = plain.addFrame(sequence.load(i));
    const msf::FrameResult b = prior.addFrame(sequence.load(i));
    const cv::Mat had_depth = a.fused.depth > 0.f;
    // What the frame saw stays; only its holes change.
    EXPECT_EQ(cv::countNonZero((a.fused.depth != b.fused.depth) & had_depth), 0) << "frame " << i;
    const int holes_before = cv::countNonZero(~had_depth), holes_after = cv::countNonZero(~(b.fused.depth > 0.f));
    if (i == 0)
      EXPECT_EQ(holes_after, holes_before) << "the first frame has no map to take depth from";
    else
      EXPECT_LT(holes_after, holes_before) << "frame " << i << ": the map filled no hole";
    const cv::Mat filled = (b.fused.depth > 0.f) & ~had_depth;
    EXPECT_EQ(cv::countNonZero(filled & (b.fused.weight <= 0.f)), 0) << "a filled pixel without its weight";
  }
  msf::test::TempDir a, b;
  EXPECT_TRUE(savedMap(plain, a) == savedMap(prior, b)) << "the map's depth went back into the map";
}

TEST_F(PipelineTest, TheSmallHolesFillTheFusedDepthAtWeightZeroAndLeaveTheMapAsItWas) {
  const msf::Sequence sequence(dataset());
  msf::PipelineConfig without;
  without.fusion.hole_fill_px = 0;
  msf::Reconstructor plain(sequence.calibration(), without);
  msf::Reconstructor filling(sequence.calibration(), msf::PipelineConfig{}); // the default fills
  for (std::size_t i = 0; i < 2; ++i) {
    const msf::FrameResult a = plain.addFrame(sequence.load(i));
    const msf::FrameResult b = filling.addFrame(sequence.load(i));
    const cv::Mat had_depth = a.fused.depth > 0.f;
    EXPECT_EQ(cv::countNonZero((a.fused.depth != b.fused.depth) & had_depth), 0) << "frame " << i;
    const cv::Mat filled = (b.fused.depth > 0.f) & ~had_depth;
    EXPECT_GT(cv::countNonZero(filled), 0) << "frame " << i << ": no hole filled";
    EXPECT_EQ(cv::countNonZero(filled & (b.fused.weight != 0.f)), 0) << "a filled pixel with a weight";
    EXPECT_EQ(cv::countNonZero(filled & b.sky), 0) << "the open sky filled";
  }
  msf::test::TempDir a, b;
  EXPECT_TRUE(savedMap(plain, a) == savedMap(filling, b)) << "a filled pixel went into the map";
}
