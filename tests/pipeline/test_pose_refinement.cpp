// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// A GPS/INS's poses refined by the LiDAR (msf_reconstruct -poses refine, the default for them):
// on a synthetic drive whose dataset poses drift as an INS's do while its truth is known, the
// refined poses come back to the truth and the mesh to the exact poses' quality; the dataset's
// poses stay available untouched.
#include <msf/common/exceptions.h>
#include <msf/io/poses.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/synthetic/ins_error.h>
#include <msf/synthetic/synthetic_generator.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <cmath>
#include <filesystem>
#include <map>

namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 25;

double headingDeg(const Eigen::Isometry3d& error) { return Eigen::AngleAxisd(error.linear()).angle() * 180.0 / M_PI; }

/// The street with INS-like poses, generated once per build under a lock (as PipelineTest's).
class InsDrive : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    const fs::path root = fs::absolute("test_data");
    fs::create_directories(root);
    dataset_ = (root / ("street_" + std::to_string(kFrames) + "_frames_ins_poses")).string();
    const int lock = ::open((root / "street_ins.lock").c_str(), O_CREAT | O_RDWR, 0644);
    ASSERT_GE(lock, 0);
    ::flock(lock, LOCK_EX);
    if (!fs::exists(fs::path(dataset_) / "gt" / "poses.txt")) {
      fs::remove_all(dataset_);
      msf::synthetic::SyntheticGenerator(config()).writeDataset(dataset_);
    }
    ::flock(lock, LOCK_UN);
    ::close(lock);
  }
  static msf::synthetic::SyntheticConfig config() {
    msf::synthetic::SyntheticConfig c;
    c.frames = kFrames;
    c.ins_poses = true;
    return c;
  }
  /// msf_reconstruct's output folder for `poses` ("" for the default), each run once for the suite.
  static std::string reconstruct(const std::string& poses) {
    auto found = runs_.find(poses);
    if (found != runs_.end())
      return found->second;
    const std::string out = runs_dir_.file("run_" + std::to_string(runs_.size()));
    const auto r = msf::test::runTool("msf_reconstruct", dataset_ + " -o " + out + " -panels 0" +
                                                             (poses.empty() ? "" : " -poses " + poses));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return runs_[poses] = out;
  }
  static std::string summary(const std::string& poses) { return readFile(reconstruct(poses) + "/summary.json"); }
  inline static msf::test::TempDir runs_dir_;
  inline static std::map<std::string, std::string> runs_;
  inline static std::string dataset_;
};

TEST_F(InsDrive, TheDatasetsPosesErrAsAnInsAndTheTruthIsBesideThem) {
  const msf::Sequence sequence(dataset_);
  ASSERT_EQ(sequence.referencePoses().size(), static_cast<std::size_t>(kFrames));
  EXPECT_TRUE(sequence.posesAreMeasured());
  EXPECT_EQ(sequence.referencePosesName(), "the synthetic ground truth (gt/poses.txt)");
  const msf::PoseList truth = msf::synthetic::SyntheticGenerator(config()).poses();
  double worst_position = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_TRUE(sequence.referencePoses()[i].isApprox(truth[i], 1e-6)) << "frame " << i;
    const Eigen::Isometry3d error = truth[i].inverse() * sequence.poses()[i];
    // The heading drifts at 0.3 degrees a second from frame 0, about the vertical alone.
    EXPECT_NEAR(headingDeg(error), 0.3 * static_cast<double>(i) / 10.0, 1e-4) << "frame " << i;
    worst_position = std::max(worst_position, (sequence.poses()[i].translation() - truth[i].translation()).norm());
  }
  EXPECT_TRUE(sequence.poses().front().isApprox(truth.front(), 1e-9));
  EXPECT_GT(worst_position, 0.3); // decimetres to metres within 2.4 s
  EXPECT_LT(worst_position, 3.0);
}

TEST_F(InsDrive, RefinedPosesComeBackToTheTruthAndTheMeshToTheExactPosesQuality) {
  const std::string exact = summary(dataset_ + "/gt/poses.txt"), refined = summary(""),
                    estimated = summary("estimate"), measured = summary("dataset");
  EXPECT_NE(refined.find("refined by LiDAR odometry"), std::string::npos); // the default for INS poses
  const auto ate = [](const std::string& json) { return jsonNumber(json, "ate_rmse_m", "trajectory"); };
  const auto accuracy = [](const std::string& json) { return jsonNumber(json, "accuracy_mean_m", "mesh_accuracy"); };
  const auto completeness = [](const std::string& json) { return jsonNumber(json, "completeness", "mesh_accuracy"); };
  // Trajectories against the truth (protocol 5): the INS's metres, the odometry's centimetres.
  EXPECT_GT(ate(measured), 0.3);
  EXPECT_LT(ate(refined), 2.0 * ate(estimated));
  EXPECT_LT(ate(refined), 0.1);
  EXPECT_LT(ate(exact), 1e-6);
  // The mesh against the true surface (protocol 3): as near and as complete as with the truth.
  EXPECT_LT(accuracy(refined), accuracy(exact) + 0.01);
  EXPECT_GT(completeness(refined), completeness(exact) - 0.01);
  EXPECT_GT(accuracy(measured), accuracy(exact) + 0.05); // what the INS's poses alone give
}

TEST_F(InsDrive, DatasetPosesStayTheFilesPosesUntouched) {
  const msf::Sequence sequence(dataset_);
  const msf::PoseList used = msf::loadOdometryPoses(reconstruct("dataset") + "/poses.txt");
  ASSERT_EQ(used.size(), static_cast<std::size_t>(kFrames));
  for (std::size_t i = 0; i < used.size(); ++i)
    EXPECT_TRUE(used[i].isApprox(sequence.poses()[i], 1e-6)) << "frame " << i;
}

TEST_F(PipelineTest, RefineNeedsEachFramesOwnPose) {
  const msf::Sequence sequence(dataset());
  msf::Reconstructor::Options options;
  options.poses = msf::Reconstructor::PoseMode::Refine;
  msf::Reconstructor engine(sequence.calibration(), msf::PipelineConfig{}, options);
  msf::Frame frame = sequence.load(0);
  frame.has_pose = false;
  EXPECT_NE(msf::test::errorOf([&] { engine.addFrame(frame); }).find("frame 0 has no pose to refine"),
            std::string::npos);
}

TEST_F(PipelineTest, RefinedExactPosesStayExactAlikeInBothWaysOfFeedingTheEngine) {
  // The street's exact poses as the prior: the scans agree with them, so refining keeps them
  // to within the odometry's centimetres; fed frame by frame or run overlapped, the same poses.
  const msf::Sequence sequence(dataset());
  const auto frames = sequence.indices(msf::FrameRange::parse("0:"));
  msf::Reconstructor::Options options;
  options.poses = msf::Reconstructor::PoseMode::Refine;
  msf::Reconstructor overlapped(sequence.calibration(), msf::PipelineConfig{}, options);
  msf::PoseList run_poses;
  overlapped.run(sequence, frames, [&](msf::FrameResult& r) { run_poses.push_back(r.T_world_cam0); });
  ASSERT_EQ(run_poses.size(), frames.size());
  msf::Reconstructor one_by_one(sequence.calibration(), msf::PipelineConfig{}, options);
  for (std::size_t i : frames) {
    const msf::FrameResult r = one_by_one.addFrame(sequence.load(i));
    EXPECT_TRUE(r.T_world_cam0.isApprox(run_poses[i], 1e-9)) << "frame " << i;
    EXPECT_LT((run_poses[i].translation() - sequence.poses()[i].translation()).norm(), 0.05) << "frame " << i;
    EXPECT_LT(headingDeg(sequence.poses()[i].inverse() * run_poses[i]), 0.1) << "frame " << i;
  }
}

} // namespace
