// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The pipeline on a small synthetic sequence: same depth as the chain of tools, a sane
// summary, a clean stop, and clear errors.
#include <msf/common/output_folder.h>
#include <msf/common/config.h>
#include <msf/common/yaml_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/version.h>
#include <msf/fusion/point_types.h>
#include <msf/io/cloud_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/bounded_queue.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/synthetic/synthetic_generator.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <sys/file.h>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

namespace {

TEST_F(PipelineTest, FusedDepthEqualsTheChainOfTools) {
  const msf::Sequence sequence(dataset());
  const msf::Frame frame = sequence.load(1);
  // The engine's depth once the map took the frame: its small holes filled at weight 0, as msf_fuse's.
  msf::Reconstructor pipeline(sequence.calibration(), msf::PipelineConfig{});
  const msf::FrameResult result = pipeline.addFrame(frame);

  msf::test::TempDir out;
  const std::string calib = sequence.directory() + "/calib.txt";
  const std::string steps[][2] = {
      {"msf_interpolate", sequence.scanPath(1) + " " + out.file("lidar.pcd") + " -calib " + calib},
      {"msf_stereo", sequence.imagePath(0, 1) + " " + sequence.imagePath(1, 1) + " " + out.file("stereo.pcd") +
                         " -calib " + calib + " -color " + sequence.imagePath(2, 1) + " -prior " + out.file("lidar.pcd")},
      {"msf_fuse", out.file("lidar.pcd") + " " + out.file("stereo.pcd") + " " + out.file("fused.pcd") + " -calib " +
                       calib + " -left " + sequence.imagePath(0, 1) + " -color " + sequence.imagePath(2, 1)},
  };
  for (const auto& step : steps) {
    const auto r = msf::test::runTool(step[0], step[1]);
    ASSERT_EQ(r.exit_code, 0) << step[0] << ": " << r.err;
  }
  pcl::PointCloud<msf::PointXYZRGBWeight> chained;
  msf::loadCloud(out.file("fused.pcd"), chained);
  const cv::Mat a = result.fused.depth, b = msf::cloudToDepthImage(chained);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(cv::countNonZero(a), a.total() / 2);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << "fused depth differs between the pipeline and the tools";
  EXPECT_GT(cv::countNonZero((result.fused.depth > 0) & (result.fused.weight == 0.f)), 0) << "no small hole filled";
  // Both sides were guided by the real returns (stereo.guidance lidar, the default): without
  // guidance the depth differs.
  msf::PipelineConfig unguided;
  unguided.stereo.guidance = "none";
  msf::Reconstructor plain(sequence.calibration(), unguided);
  EXPECT_GT(cv::norm(a, plain.addFrame(frame).fused.depth, cv::NORM_INF), 0.0);
}

TEST_F(PipelineTest, TheChainOfToolsGivesTheEnginesMapByteForByte) {
  // msf_interpolate -canvas, msf_stereo, msf_fuse, then msf_integrate with the scans: the fusion
  // grows the frame onto the LiDAR's canvas and carries its free-space weight and open sky, so the
  // map is the one msf_reconstruct integrates.
  const msf::Sequence sequence(dataset());
  msf::test::TempDir out;
  const std::string calib = " -calib " + sequence.directory() + "/calib.txt";
  std::string fused;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    const std::string lidar = out.file("lidar_" + std::to_string(i) + ".pcd");
    const std::string stereo = out.file("stereo_" + std::to_string(i) + ".pcd");
    fused += " " + out.file("fused_" + std::to_string(i) + ".pcd");
    const std::string colour = " -color " + sequence.imagePath(2, i);
    const std::string steps[][2] = {
        {"msf_interpolate", sequence.scanPath(i) + " " + lidar + calib + " -canvas"},
        {"msf_stereo", sequence.imagePath(0, i) + " " + sequence.imagePath(1, i) + " " + stereo + calib + colour +
                           " -prior " + lidar},
        {"msf_fuse", lidar + " " + stereo + " " + out.file("fused_" + std::to_string(i) + ".pcd") + calib + colour +
                         " -left " + sequence.imagePath(0, i)},
    };
    for (const auto& step : steps) {
      const auto r = msf::test::runTool(step[0], step[1]);
      ASSERT_EQ(r.exit_code, 0) << step[0] << ": " << r.err;
    }
  }
  // The rig file says what calib.txt cannot: the synthetic scans are snapshots (no sweep's skew).
  auto r = msf::test::runTool("msf_integrate", fused + " -poses " + dataset() + "/poses/00.txt" + " -rig " +
                                                   sequence.directory() + "/rig.yaml -scans " + sequence.directory() +
                                                   "/velodyne -o " + out.file("volume.pcd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = msf::test::runTool("msf_reconstruct", dataset() + " -panels 0 -o " + out.file("run"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string chained = readFile(out.file("volume.pcd")), engine = readFile(out.file("run/volume.pcd"));
  EXPECT_GT(engine.size(), 100000u);
  EXPECT_TRUE(chained == engine) << "the volume of the tools differs from msf_reconstruct's";
  // ... and so is the mesh: msf_mesh of the tools' volume, with the run's configuration, is
  // msf_reconstruct's mesh byte for byte (the blocks a run allocated but never observed, which
  // the file omits, change nothing).
  r = msf::test::runTool("msf_mesh", out.file("volume.pcd") + " " + out.file("mesh.ply") + " -config " +
                                         out.file("run/config.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(readFile(out.file("mesh.ply")) == readFile(out.file("run/mesh.ply")))
      << "msf_mesh of the volume differs from msf_reconstruct's mesh";
  // The fused clouds are the canvas, and carry the open sky the map is carved along.
  pcl::PointCloud<msf::PointXYZRGBWeight> first;
  msf::loadCloud(out.file("fused_0.pcd"), first);
  EXPECT_GT(first.width, static_cast<std::uint32_t>(sequence.calibration().image_size.width));
  EXPECT_GT(std::count_if(first.begin(), first.end(), [](const auto& p) { return !std::isnan(p.sky_depth); }), 1000);
}

TEST_F(PipelineTest, RunIntegratesEveryFrameInOrderAndStopsCleanly) {
  const msf::Sequence sequence(dataset());
  const auto frames = sequence.indices(msf::FrameRange::parse("0:"));
  {
    msf::Reconstructor pipeline(sequence.calibration(), msf::PipelineConfig{});
    std::vector<std::size_t> seen;
    const auto stats = pipeline.run(sequence, frames, [&](msf::FrameResult& r) {
      seen.push_back(r.index);
      EXPECT_GT(r.times.integrate_ms, 0.0);
      EXPECT_EQ(r.name, sequence.frameName(r.index));
    });
    EXPECT_EQ(seen, frames);
    EXPECT_EQ(stats.frames_done, frames.size());
    EXPECT_FALSE(stats.interrupted);
    EXPECT_GT(pipeline.mesh().triangles.size(), 1000u);
  }
  {
    // A stop during the first frame: it is finished, the frames behind it are dropped.
    msf::Reconstructor pipeline(sequence.calibration(), msf::PipelineConfig{});
    std::atomic<bool> stop{false};
    const auto stats = pipeline.run(sequence, frames, [&](msf::FrameResult&) { stop = true; }, &stop);
    EXPECT_TRUE(stats.interrupted);
    EXPECT_EQ(stats.frames_done, 1u);
    EXPECT_GT(pipeline.mesh().triangles.size(), 100u);
  }
}

TEST_F(PipelineTest, AFailingStageStopsTheRunWithItsError) {
  const msf::Sequence sequence(dataset());
  msf::Reconstructor pipeline(sequence.calibration(), msf::PipelineConfig{});
  EXPECT_THROW(pipeline.run(sequence, {0, 1, 99}, nullptr), msf::InvalidInputError); // frame 99 does not exist
}

TEST_F(PipelineTest, ReconstructWritesItsOutputsWithSaneFigures) {
  msf::test::TempDir out;
  const auto r = msf::test::runTool("msf_reconstruct", dataset() + " -o " + out.path() + " -panels 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* file : {"mesh.ply", "volume.pcd", "summary.json", "frames.csv", "runtime.png", "mesh_preview.png",
                           "report.md", "depth_000000.png", "depth_000003.png"})
    EXPECT_TRUE(msf::test::fileExists(out.file(file))) << file;
  const std::string json = readFile(out.file("summary.json"));
  // The run names the build that made it.
  EXPECT_NE(json.find(std::string("\"msfusion\": {\"version\": \"") + msf::versionString() + "\", \"commit\": \"" +
                      msf::gitCommit() + "\"}"),
            std::string::npos)
      << json;
  EXPECT_EQ(jsonNumber(json, "frames"), 4);
  EXPECT_GT(jsonNumber(json, "frames_per_second"), 0.0);
  // The first frame is done before the run ends, and the three after it take the rest.
  EXPECT_GT(jsonNumber(json, "first_frame_s"), 0.0);
  EXPECT_LT(jsonNumber(json, "first_frame_s"), jsonNumber(json, "wall_s"));
  const double after_first = 3.0 / (jsonNumber(json, "wall_s") - jsonNumber(json, "first_frame_s"));
  EXPECT_NEAR(jsonNumber(json, "frames_per_second_after_first"), after_first, 0.02 * after_first); // 1 ms rounding
  EXPECT_GT(jsonNumber(json, "peak_memory_mb"), 10.0);
  EXPECT_LT(jsonNumber(json, "peak_memory_mb"), 4096.0);
  EXPECT_GT(jsonNumber(json, "median", "stereo"), 0.0);
  EXPECT_GE(jsonNumber(json, "p95", "integrate"), jsonNumber(json, "median", "integrate"));
  EXPECT_GT(jsonNumber(json, "triangles"), 1000);
  // Synthetic ground truth: each depth method is scored; fusion is at least as good as
  // each input on D1 with missing estimates counted as bad.
  const double d1_sgbm = jsonNumber(json, "d1_all", "sgbm");
  const double d1_lidar = jsonNumber(json, "d1_all", "interpolated");
  const double d1_fused = jsonNumber(json, "d1_all", "fused");
  for (double d1 : {d1_sgbm, d1_lidar, d1_fused}) {
    EXPECT_GE(d1, 0.0);
    EXPECT_LE(d1, 1.0);
  }
  EXPECT_LT(d1_fused, d1_sgbm);
  EXPECT_LT(jsonNumber(json, "accuracy_mean_m"), 0.3);
  EXPECT_GT(jsonNumber(json, "completeness"), 0.3);
  // Protocol 4 on the exact depth, the moving cars' pixels apart.
  EXPECT_NE(json.find("\"moving_split\": true"), std::string::npos);
  EXPECT_EQ(jsonNumber(json, "gt_pixels", "reconstruction_evaluation"), jsonNumber(json, "gt_pixels", "fused"));
  EXPECT_GT(jsonNumber(json, "coverage", "reconstruction_evaluation"), 0.3); // the mesh's row comes first
  // frames.csv: a header and one row per frame.
  std::istringstream csv(readFile(out.file("frames.csv")));
  std::string line;
  int rows = 0;
  while (std::getline(csv, line))
    ++rows;
  EXPECT_EQ(rows, 5);
  pcl::PolygonMesh mesh;
  msf::loadMesh(out.file("mesh.ply"), mesh);
  EXPECT_GT(mesh.polygons.size(), 1000u);
}

/// Runs msf_reconstruct on `dataset` into `out` (-panels 0), reading its stdout and stderr
/// line by line: `on_line(line, pid)` may signal it. Returns its wait status.
int runReconstructReading(const std::string& dataset, const std::string& out, const std::function<void(const std::string&, pid_t)>& on_line) {
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0)
    throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  const std::string tool = msf::test::binDir() + "/msf_reconstruct";
  const pid_t pid = ::fork();
  if (pid < 0)
    throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    ::dup2(pipe_fds[1], STDOUT_FILENO);
    ::dup2(pipe_fds[1], STDERR_FILENO);
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    ::execl(tool.c_str(), tool.c_str(), dataset.c_str(), "-o", out.c_str(), "-panels", "0",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(pipe_fds[1]);
  FILE* child_out = ::fdopen(pipe_fds[0], "r");
  char line[4096];
  std::string output;
  while (std::fgets(line, sizeof line, child_out)) {
    output += line;
    on_line(line, pid);
  }
  std::fclose(child_out);
  int status = 0;
  ::waitpid(pid, &status, 0);
  msf::test::expectNoSanitizerReport(output, tool + " " + dataset + " -o " + out + " -panels 0");
  return status;
}

/// The names in a folder, sorted.
std::vector<std::string> entriesOf(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// An interrupted run's outputs, beside nothing else in `dir`: a loadable mesh of at least
/// one frame, a summary.json that parses and says so, and no staging folder or temporary.
/// Returns the summary.
std::string expectInterruptedOutputs(const msf::test::TempDir& dir, const std::string& out) {
  EXPECT_EQ(entriesOf(dir.path()), std::vector<std::string>{"out"}) << "a staging folder or temporary is left beside OUT";
  for (const auto& e : std::filesystem::directory_iterator(out))
    if (e.path().filename() != msf::OutputFolder::manifestName()) {
      EXPECT_NE(e.path().filename().string()[0], '.') << "a temporary is left in OUT: " << e.path();
    }
  const std::string json = readFile(out + "/summary.json");
  // Parsed by a JSON parser (Python's; OpenCV's takes no null), not only searched.
  const auto parsed = msf::test::runCommand(
      "python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); "
      "print(s[\"interrupted\"], s[\"frames\"], \",\".join(s[\"skipped\"]))' " +
      out + "/summary.json");
  EXPECT_EQ(parsed.exit_code, 0) << parsed.err;
  EXPECT_EQ(parsed.out.rfind("True ", 0), 0u) << parsed.out;
  EXPECT_NE(json.find("\"interrupted\": true"), std::string::npos) << json;
  EXPECT_GE(jsonNumber(json, "frames"), 1);
  EXPECT_LE(jsonNumber(json, "frames"), 3);
  EXPECT_NE(readFile(out + "/report.md").find("(interrupted"), std::string::npos);
  pcl::PolygonMesh mesh;
  EXPECT_NO_THROW(msf::loadMesh(out + "/mesh.ply", mesh));
  EXPECT_GT(mesh.polygons.size(), 100u);
  return json;
}

TEST_F(PipelineTest, CtrlCStillWritesTheMeshAndTheSummary) {
  msf::test::TempDir dir;
  const std::string out = dir.file("out");
  bool interrupted = false;
  // Interrupt as soon as the first frame is integrated.
  const int status = runReconstructReading(dataset(), out, [&](const std::string& line, pid_t pid) {
    if (!interrupted && line.find("(1/4)") != std::string::npos) {
      ::kill(pid, SIGINT);
      interrupted = true;
    }
  });
  ASSERT_TRUE(interrupted) << "the tool printed no progress line";
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const std::string json = expectInterruptedOutputs(dir, out);
  // One stop: the optional work is done (the street's mesh is scored).
  EXPECT_NE(json.find("\"skipped\": []"), std::string::npos) << json;
  EXPECT_GT(jsonNumber(json, "accuracy_mean_m"), 0.0);
}

TEST_F(PipelineTest, ASecondCtrlCStillLeavesAValidMeshAndSummary) {
  msf::test::TempDir dir;
  const std::string out = dir.file("out");
  // The first SIGINT once the first frame is integrated; each next signal once the tool said
  // it got the previous one (two pending SIGINTs would be delivered as one). The second
  // SIGINT comes while the frames under way finish, well before the mesh is written; the
  // third signal, a SIGTERM, during the rest.
  const char* const acknowledgements[] = {"msf_reconstruct: stopping after the frames under way",
                                          "msf_reconstruct: skipping the mesh's scores"};
  int sent = 0;
  std::string output;
  const int status = runReconstructReading(dataset(), out, [&](const std::string& line, pid_t pid) {
    output += line;
    if (sent == 0 && line.find("(1/4)") != std::string::npos) {
      ::kill(pid, SIGINT);
      ++sent;
    } else if ((sent == 1 || sent == 2) && line.find(acknowledgements[sent - 1]) != std::string::npos) {
      ::kill(pid, sent == 1 ? SIGINT : SIGTERM);
      ++sent;
    }
  });
  ASSERT_EQ(sent, 3) << "the tool did not acknowledge each signal:\n" << output;
  ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << WTERMSIG(status) << ":\n" << output;
  EXPECT_EQ(WEXITSTATUS(status), 130) << output;
  const std::string json = expectInterruptedOutputs(dir, out);
  // Stopped twice: the mesh is not scored, and the summary says what was skipped.
  EXPECT_NE(json.find("\"skipped\": [\"mesh_preview\", \"mesh_accuracy\", \"reconstruction_evaluation\", \"open_sky\"]"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"mesh_accuracy\": null"), std::string::npos) << json;
  EXPECT_FALSE(msf::test::fileExists(out + "/mesh_preview.png"));
  EXPECT_NE(readFile(out + "/report.md").find("Stopped a second time: skipped `mesh_preview`"), std::string::npos);
}

TEST_F(PipelineTest, AReaderThatGoesStopsTheRunOnceAndTheRunStillEnds) {
  // `msf_reconstruct ... | head -n 3`: the pipe's reader goes after the first frame's line. The
  // SIGPIPE that follows is one stop request, and the writes after it are no more requests: the
  // handler's message to the same closed pipe used to raise SIGPIPE again, for ever. A SIGKILL
  // after two minutes fails the test instead of hanging it.
  for (const bool stderr_too : {true, false}) {
    msf::test::TempDir dir, logs;
    const std::string out = dir.file("out"), err = logs.file("err");
    const auto r = msf::test::runCommand("bash -c 'timeout -s KILL 120 " + msf::test::binDir() + "/msf_reconstruct " +
                                         dataset() + " -o " + out + " -panels 0 " +
                                         (stderr_too ? "2>&1" : "2>" + err) + " | head -n 3; exit ${PIPESTATUS[0]}'");
    ASSERT_EQ(r.exit_code, 130) << "stderr to the pipe too: " << stderr_too << "\n" << r.out << r.err;
    const std::string json = expectInterruptedOutputs(dir, out);
    EXPECT_NE(json.find("\"skipped\": []"), std::string::npos) << "one request, not a second: " << json;
    if (!stderr_too) {
      const std::string said = readFile(err);
      EXPECT_NE(said.find("msf_reconstruct: stopping after the frames under way"), std::string::npos) << said;
      EXPECT_EQ(said.find("msf_reconstruct: skipping"), std::string::npos) << said;
    }
  }
}

TEST_F(PipelineTest, AKilledRunLeavesThePreviousOutputAndTheNextRunRemovesItsStaging) {
  msf::test::TempDir dir;
  const std::string out = dir.file("out");
  std::filesystem::create_directories(out);
  std::ofstream(out + "/summary.json") << "{\"previous\": true}\n";
  std::ofstream(out + "/.msf_manifest") << "# an earlier output\nsummary.json\n";
  // SIGKILL once the first frame is integrated: the run's files are in its staging folder.
  bool killed = false;
  const int status = runReconstructReading(dataset(), out, [&](const std::string& line, pid_t pid) {
    if (!killed && line.find("(1/4)") != std::string::npos) {
      ::kill(pid, SIGKILL);
      killed = true;
    }
  });
  ASSERT_TRUE(killed) << "the tool printed no progress line";
  ASSERT_TRUE(WIFSIGNALED(status));
  const std::vector<std::string> beside = entriesOf(dir.path());
  ASSERT_EQ(beside.size(), 2u) << "expected OUT and the killed run's staging folder";
  EXPECT_EQ(beside[0].rfind(".out.partial.", 0), 0u) << beside[0];
  EXPECT_EQ(entriesOf(out), (std::vector<std::string>{".msf_manifest", "summary.json"})) << "the killed run changed OUT";
  EXPECT_EQ(readFile(out + "/summary.json"), "{\"previous\": true}\n");
  // The next run replaces OUT as a whole and removes the dead run's staging folder.
  const auto r = msf::test::runTool("msf_reconstruct", dataset() + " -frames 0:0 -panels 0 -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(entriesOf(dir.path()), std::vector<std::string>{"out"}) << "a staging folder is left beside OUT";
  EXPECT_EQ(readFile(out + "/summary.json").find("previous"), std::string::npos);
  pcl::PolygonMesh mesh;
  EXPECT_NO_THROW(msf::loadMesh(out + "/mesh.ply", mesh));
}

TEST_F(PipelineTest, AStreamedMapKeepsItsSmallPiecesAndSaysSo) {
  // The piece filter (on by default) counts a piece whole, which a streamed map's tiles, meshed
  // apart, cannot: the run streams, says the filter is not applied, and writes its mesh.
  ASSERT_GT(msf::MarchingCubes::Config().min_component_triangles, 0);
  msf::test::TempDir dir;
  const std::string out = dir.file("streamed");
  const auto r = msf::test::runTool("msf_reconstruct", dataset() + " -o " + out + " -frames 0:1 -panels 0 -stream 101");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Note: a streamed map keeps its small pieces (marching_cubes.min_component_triangles is not "
                       "applied)"),
            std::string::npos)
      << r.out;
  pcl::PolygonMesh mesh;
  EXPECT_NO_THROW(msf::loadMesh(out + "/mesh.ply", mesh));
  EXPECT_GT(mesh.polygons.size(), 1000u);
  // In memory the same frames lose their floating pieces, and the report says how many.
  const std::string whole = dir.file("whole");
  const auto w = msf::test::runTool("msf_reconstruct", dataset() + " -o " + whole + " -frames 0:1 -panels 0");
  ASSERT_EQ(w.exit_code, 0) << w.err;
  EXPECT_EQ(w.out.find("Note: a streamed map"), std::string::npos) << w.out;
  EXPECT_TRUE(std::regex_search(readFile(whole + "/report.md"),
                                std::regex("[1-9][0-9]* pieces of fewer than `marching_cubes.min_component_triangles` "
                                           "triangles that no vertex of `marching_cubes.component_keep_weight` holds")));
}

TEST(Reconstruct, BadInputIsAClearError) {
  msf::test::TempDir dir;
  auto r = msf::test::runTool("msf_reconstruct", dir.path() + " -o " + dir.file("out"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_reconstruct: error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("neither a KITTI odometry sequence"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_reconstruct", dir.path() + " -o /nonexistent/out");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("/nonexistent"), std::string::npos) << r.err;
  std::ofstream(dir.file("bad.yaml")) << "%YAML:1.0\ntsdf_volume:\n  voxel_size_m: -1\n";
  r = msf::test::runTool("msf_reconstruct", dir.path() + " -config " + dir.file("bad.yaml"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("tsdf_volume.voxel_size_m"), std::string::npos) << r.err;
  std::ofstream(dir.file("camera2.yaml")) << "%YAML:1.0\nprojection:\n  camera: 2\n";
  r = msf::test::runTool("msf_reconstruct", dir.path() + " -config " + dir.file("camera2.yaml"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("projection.camera is 2"), std::string::npos) << r.err;
  r = msf::test::runTool("msf_reconstruct", "-frames 3:1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_FALSE(msf::test::fileExists("msf_out/summary.json"));
}

TEST(PipelineConfig, ShippedFilesLoadAndBadSchedulingKeysAreNamed) {
  for (const char* name : {"kitti.yaml", "synthetic.yaml"}) {
    const msf::PipelineConfig config = msf::PipelineConfig::load(msf::test::sourceDir() + "/config/" + name);
    EXPECT_TRUE(config.scheduling.stereo_prior) << name;
  }
  msf::test::TempDir dir;
  // lidar_threads was removed (the LiDAR steps run on OpenCV's pool): named as such, whatever its value.
  for (const std::string key : {"queue_capacity: 0", "lidar_threads: 1", "mesh_every_n_frames: -2"}) {
    std::ofstream(dir.file("bad.yaml")) << "%YAML:1.0\npipeline:\n  " << key << "\n";
    try {
      msf::PipelineConfig::load(dir.file("bad.yaml"));
      ADD_FAILURE() << key << " was accepted";
    } catch (const msf::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("pipeline." + key.substr(0, key.find(':'))), std::string::npos) << e.what();
      if (key.rfind("lidar_threads", 0) == 0) {
        EXPECT_NE(std::string(e.what()).find("was removed"), std::string::npos) << e.what();
      }
    }
  }
}

TEST(PipelineConfig, ShippedFilesAreTheDefaults) {
  // One truth: msf_reconstruct without -config (make demo, the README's main command) runs
  // what the shipped files say, so their figures are the defaults' figures.
  auto printed = [](const msf::PipelineConfig& c) {
    std::ostringstream out;
    c.print(out);
    return out.str();
  };
  for (const char* name : {"kitti.yaml", "synthetic.yaml"})
    EXPECT_EQ(printed(msf::PipelineConfig::load(msf::test::sourceDir() + "/config/" + name)),
              printed(msf::PipelineConfig{}))
        << name;
}

TEST(PipelineConfig, ThePrintedConfigurationIsCompleteAndReadsBackToTheSame) {
  msf::test::TempDir dir;
  auto printed = [](const msf::PipelineConfig& c) {
    std::ostringstream out;
    c.print(out);
    return out.str();
  };
  auto reload = [&](const std::string& text) {
    std::ofstream(dir.file("config.yaml")) << text;
    return msf::PipelineConfig::load(dir.file("config.yaml"));
  };
  // A configuration with values that print with many digits, and words other than the defaults.
  msf::PipelineConfig edited;
  edited.volume.voxel_size_m = 0.07;
  edited.integrator.lambda = 5;
  edited.fusion.lidar_sigma_px = 0.123456789f;
  edited.fusion.method = msf::FusionMethod::Paper;
  edited.fusion.edge_support = false;
  edited.interpolation.combine = msf::CombineRule::Nearest;
  edited.interpolation.slice.jump_inv_per_m = 1.f / 3.f;
  edited.stereo.guidance = "none";
  edited.stereo.guidance_bridge_agreement = 0.3f;
  edited.projection.max_range_m = 80.5f;
  edited.rings.heldout_remainder = 1;
  edited.mesher.min_weight = 0.25f;
  edited.scheduling.queue_capacity = 3;
  edited.odometry.deskew = "none";
  edited.odometry.min_constraint = 0.0025;
  std::vector<std::pair<std::string, msf::PipelineConfig>> configs = {{"defaults", msf::PipelineConfig{}},
                                                                      {"edited", edited}};
  for (const char* name : {"kitti.yaml", "synthetic.yaml"})
    configs.emplace_back(name, msf::PipelineConfig::load(msf::test::sourceDir() + "/config/" + name));
  for (const auto& [name, config] : configs) {
    const std::string first = printed(config);
    const msf::PipelineConfig again = reload(first);
    EXPECT_EQ(printed(again), first) << name;
    // The dump is the whole configuration: every declared key of every section, in order.
    const YAML::Node file = msf::loadYamlFile(dir.file("config.yaml"), "config");
    msf::PipelineConfig::forEachSection(config, [&](const auto& section) {
      std::vector<std::string> declared, written;
      for (const msf::KeyText& key : msf::listKeys(section))
        declared.push_back(key.name);
      for (const auto& key : file[section.kSection])
        written.push_back(key.first.Scalar());
      EXPECT_FALSE(declared.empty()) << section.kSection;
      EXPECT_EQ(written, declared) << name << ": " << section.kSection;
    });
  }
  // The very same values, not ones near them.
  const msf::PipelineConfig again = reload(printed(edited));
  EXPECT_EQ(again.volume.voxel_size_m, 0.07);
  EXPECT_EQ(again.fusion.lidar_sigma_px, 0.123456789f);
  EXPECT_EQ(again.fusion.method, msf::FusionMethod::Paper);
  EXPECT_FALSE(again.fusion.edge_support);
  EXPECT_EQ(again.interpolation.combine, msf::CombineRule::Nearest);
  EXPECT_EQ(again.interpolation.slice.jump_inv_per_m, 1.f / 3.f);
  EXPECT_EQ(again.stereo.guidance, "none");
  EXPECT_EQ(again.stereo.guidance_bridge_agreement, 0.3f);
  EXPECT_EQ(again.projection.max_range_m, 80.5f);
  EXPECT_EQ(again.rings.heldout_remainder, 1);
  EXPECT_EQ(again.mesher.min_weight, 0.25f);
  EXPECT_EQ(again.scheduling.queue_capacity, 3);
  EXPECT_EQ(again.integrator.lambda, 5.0);
  EXPECT_EQ(again.odometry.deskew, "none");
  EXPECT_EQ(again.odometry.min_constraint, 0.0025);
}

TEST(BoundedQueue, BlocksWhenFullAndDrainsAfterClose) {
  msf::BoundedQueue<int> queue(2);
  EXPECT_TRUE(queue.push(1));
  EXPECT_TRUE(queue.push(2));
  std::atomic<bool> third_pushed{false};
  std::thread producer([&] {
    queue.push(3);
    third_pushed = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(third_pushed); // full: the producer waits
  EXPECT_EQ(queue.pop().value(), 1);
  producer.join();
  EXPECT_TRUE(third_pushed);
  queue.close();
  EXPECT_FALSE(queue.push(4));
  EXPECT_EQ(queue.pop().value(), 2);
  EXPECT_EQ(queue.pop().value(), 3);
  EXPECT_FALSE(queue.pop().has_value());
}

TEST(BoundedQueue, PushNewestDropsTheOldestAndNeverBlocks) {
  msf::BoundedQueue<int> queue(2);
  EXPECT_FALSE(queue.pushNewest(1));
  EXPECT_FALSE(queue.pushNewest(2));
  EXPECT_TRUE(queue.pushNewest(3)); // full: 1 makes room
  EXPECT_TRUE(queue.pushNewest(4)); // and 2
  EXPECT_EQ(queue.pop().value(), 3);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(queue.popFor(std::chrono::seconds(5)).value(), 4);
  EXPECT_FALSE(queue.popFor(std::chrono::milliseconds(20)).has_value()); // empty: runs out
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  EXPECT_FALSE(queue.drained());
  EXPECT_FALSE(queue.pushNewest(5));
  queue.close();
  EXPECT_FALSE(queue.pushNewest(6)); // closed: refused
  EXPECT_EQ(queue.popFor(std::chrono::seconds(5)).value(), 5);
  EXPECT_TRUE(queue.drained());
  EXPECT_FALSE(queue.popFor(std::chrono::seconds(5)).has_value()); // at once
}

} // namespace
