// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "batch_fixture.h"
#include "store_difference.h"

#include <msf/batch/batch_plan.h>
#include <msf/batch/batch_tasks.h>
#include <msf/batch/drive_list.h>
#include <msf/batch/slurm_jobs.h>
#include <msf/batch/subprocess.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/tsdf_store.h>

#include <filesystem>
#include <fstream>

using namespace msf;
namespace fs = std::filesystem;

namespace {

std::string batchTool() { return test::binDir() + "/msf_batch"; }

BatchOptions optionsFor(const std::string& config, const std::string& frames = "0:") {
  BatchOptions o;
  o.batch = batchTool();
  o.reconstruct = test::binDir() + "/msf_reconstruct";
  o.config = config;
  o.frames = frames;
  o.stream_m = 120;
  o.merge_tasks = 2;
  return o;
}

TEST(BatchTask, ReadsWhatItWrites) {
  for (const char* text : {"drive:0", "drive:12", "merge:1", "mesh:3", "finish"})
    EXPECT_EQ(BatchTask::parse(text).text(), text);
  for (const char* bad : {"drive", "drive:", "drive:-1", "drive:x", "mesh:1:2", "finish:1", "merges:1"})
    EXPECT_NE(test::errorOf([&] { BatchTask::parse(bad); }).find(std::string("'") + bad + "'"), std::string::npos)
        << bad;
}

TEST(Subprocess, AppendsItsOutputToALogAndGivesItsStatus) {
  test::TempDir dir;
  const std::string log = dir.file("task.log");
  EXPECT_EQ(Subprocess({"sh", "-c", "echo first; echo to-stderr >&2; exit 3"}, log).wait(), 3);
  EXPECT_EQ(Subprocess({"sh", "-c", "echo second"}, log).wait(), 0);
  EXPECT_EQ(test::readText(log), "first\nto-stderr\nsecond\n");
  EXPECT_EQ(Subprocess({"sh", "-c", "kill -9 $$"}, log).wait(), 128 + 9);
  EXPECT_NE(test::errorOf([&] { Subprocess({"/no/such/program"}, log); }).find("/no/such/program"), std::string::npos);
  const CommandOutput out = captureCommand({"sh", "-c", "echo out; echo err >&2; exit 2"});
  EXPECT_EQ(out.status, 2);
  EXPECT_EQ(out.out, "out\n");
  EXPECT_EQ(out.err, "err\n");
  EXPECT_EQ(shellQuote({"a b", "it's", "plain/path-1.0"}), "'a b' 'it'\\''s' plain/path-1.0");
}

class BatchPlanTest : public test::BatchDrives {};

TEST_F(BatchPlanTest, FindsDrivesUnderARootAndInAList) {
  const std::string root = fs::path(drives().front()).parent_path().string();
  std::vector<Drive> found = findDrives(root);
  nameDrives(found);
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].name, "a_from_start"); // a synthetic street is named by its root
  EXPECT_EQ(found[2].name, "c_back_from_44m");
  EXPECT_EQ(found[0].dataset, (fs::path(drives()[0]) / "sequences" / "00").string());

  test::TempDir dir;
  std::ofstream(dir.file("drives.txt")) << "# two drives\n" << drives()[0] << "\n\n  " << drives()[1] << "\t"
                                        << drives()[0] << "/poses/00.txt\n";
  std::vector<Drive> listed = readDriveList(dir.file("drives.txt"));
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_EQ(listed[1].poses, drives()[0] + "/poses/00.txt");
  std::ofstream(dir.file("bad.txt")) << drives()[0] << "\n" << dir.path() << "\n";
  EXPECT_NE(test::errorOf([&] { readDriveList(dir.file("bad.txt")); }).find("line 2"), std::string::npos);
  std::vector<Drive> twice = {found[0], found[0]};
  EXPECT_NE(test::errorOf([&] { nameDrives(twice); }).find("given twice"), std::string::npos);
  EXPECT_NE(test::errorOf([&] { findDrives(dir.path()); }).find("holds no drive"), std::string::npos);
}

/// A user's own recordings: folders of the generic layout and ROS bags (known by their first
/// bytes: nothing else is read before the plan), beside a KITTI sequence.
TEST(DriveList, FindsFoldersOfTheGenericLayoutAndBags) {
  test::TempDir dir;
  for (const char* sub : {"left", "right", "lidar"})
    fs::create_directories(dir.file("root/van_monday") + "/" + sub);
  std::ofstream(dir.file("root/night_drive.bag")) << "#ROSBAG V2.0\n";
  std::ofstream(dir.file("root/notes.bag")) << "not a bag\n";
  std::vector<Drive> found = findDrives(dir.file("root"));
  nameDrives(found);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].name, "night_drive");
  EXPECT_EQ(found[0].dataset, dir.file("root/night_drive.bag"));
  EXPECT_EQ(found[1].name, "van_monday");
  EXPECT_EQ(findDrives(dir.file("root/night_drive.bag")).size(), 1u);
  EXPECT_EQ(findDrives(dir.file("root/van_monday")).front().dataset, dir.file("root/van_monday"));

  std::ofstream(dir.file("root/drives.txt")) << "van_monday\nnight_drive.bag\nnotes.bag\n";
  const std::string error = test::errorOf([&] { readDriveList(dir.file("root/drives.txt")); });
  EXPECT_NE(error.find("line 3: 'notes.bag' is not a drive"), std::string::npos) << error;
  EXPECT_NE(error.find("a ROS bag"), std::string::npos) << error;
  std::ofstream(dir.file("root/drives.txt")) << "van_monday\nnight_drive.bag\n";
  EXPECT_EQ(readDriveList(dir.file("root/drives.txt")).size(), 2u);

  // A folder without its rig file: the batch, which takes no -rig, says how to make one it reads.
  const std::string no_rig = test::errorOf([&] { openDrive(found[1]); });
  EXPECT_NE(no_rig.find("drive 'van_monday': dataset '"), std::string::npos) << no_rig;
  EXPECT_NE(no_rig.find("has no rig.yaml"), std::string::npos) << no_rig;
  EXPECT_NE(no_rig.find("msf_convert DATASET DIR, with -rig FILE"), std::string::npos) << no_rig;
}

TEST_F(BatchPlanTest, SavesAndLoadsAndRefusesAFolderOfSomeoneElse) {
  test::TempDir dir;
  std::vector<Drive> drives = findDrives(fs::path(drives_.front()).parent_path().string());
  nameDrives(drives);
  BatchPlan plan(dir.file("out"), drives, optionsFor(config()));
  plan.setResources(1, 612.5, 768);
  plan.save();
  const BatchPlan loaded = BatchPlan::load(dir.file("out"));
  ASSERT_EQ(loaded.drives().size(), 3u);
  EXPECT_EQ(loaded.drives()[1].dataset, drives[1].dataset);
  EXPECT_EQ(loaded.requestMb(1), 768u);
  EXPECT_EQ(loaded.request(2), plan.request(2));
  EXPECT_EQ(loaded.reconstructCommand(0), plan.reconstructCommand(0));

  fs::create_directories(dir.file("theirs"));
  std::ofstream(dir.file("theirs/notes.txt")) << "mine";
  const std::string error = test::errorOf([&] { BatchPlan(dir.file("theirs"), drives, optionsFor(config())).save(); });
  EXPECT_NE(error.find("notes.txt"), std::string::npos) << error;
  EXPECT_EQ(test::readText(dir.file("theirs/notes.txt")), "mine");
  std::ofstream(dir.file("out/notes.txt")) << "mine";
  EXPECT_NE(test::errorOf([&] { plan.save(); }).find("a batch does not write"), std::string::npos);
}

TEST_F(BatchPlanTest, SlurmScriptAsksForThePredictionAndRequeuesAFailedAttempt) {
  test::TempDir dir;
  std::vector<Drive> drives = findDrives(fs::path(drives_.front()).parent_path().string());
  nameDrives(drives);
  const BatchPlan plan(dir.file("out"), drives, optionsFor(config()));
  SlurmOptions options;
  options.partition = "fast";
  const std::string script = slurmStageScript(plan, BatchTask::Kind::Drive, {0, 2}, 768, 2, options);
  for (const char* line : {"#SBATCH --array=0,2\n", "#SBATCH --mem=768M\n", "#SBATCH --cpus-per-task=2\n",
                           "#SBATCH --requeue\n", "#SBATCH --partition=fast\n", "task=drive:$SLURM_ARRAY_TASK_ID\n",
                           "-run \"$task\"\n", "-lt 2 ]", "scontrol requeue"})
    EXPECT_NE(script.find(line), std::string::npos) << line << " not in\n" << script;
  const std::string finish = slurmStageScript(plan, BatchTask::Kind::Finish, {}, 1024, 1, {});
  EXPECT_EQ(finish.find("--array"), std::string::npos);
  EXPECT_NE(finish.find("task=finish\n"), std::string::npos);
}

/// The batch on this machine, with integration as a plain weighted mean: the merged map is the
/// map of every frame integrated in one process, more complete than each drive's and as accurate.
TEST_F(BatchPlanTest, LocalBatchMergesToTheOneProcessMapAndNeverRedoesADrive) {
  test::TempDir dir;
  const std::string common = " -config '" + plainConfig() + "' -stream " + kStream + driveArguments();
  const test::CommandResult run =
      test::runCommand(batchTool() + " -o " + dir.file("batch") + " -local 2 -merge_tasks 2" + common);
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const std::string map = dir.file("batch/map");
  ASSERT_TRUE(test::fileExists(map + "/mesh.ply")) << run.out;
  ASSERT_TRUE(test::fileExists(map + "/.msf_manifest"));
  EXPECT_FALSE(fs::exists(dir.file("batch/merge"))) << "the merge's work is removed once the map is committed";
  const std::string summary = test::readText(map + "/summary.json");
  EXPECT_NE(summary.find("\"tiles_shared\": "), std::string::npos);

  const test::CommandResult one =
      test::runCommand(batchTool() + " -o " + dir.file("one") + " -one_process" + common);
  ASSERT_EQ(one.exit_code, 0) << one.out << one.err;
  const test::StoreDifference d = test::compareStores(TsdfStore::open(map), TsdfStore::open(dir.file("one")));
  EXPECT_TRUE(d.same_blocks);
  EXPECT_GT(d.observed, 100000u);
  EXPECT_LT(d.sdf, 1e-4) << "metres";
  EXPECT_LT(d.weight_relative, 1e-4);

  // More complete than any one drive's map, as accurate, and as good as one process.
  const test::StreetTruth truth(drives());
  const MeshAccuracy merged = expectBetterThanEachDrive(dir.file("batch"), truth);
  const MeshAccuracy together = truth.score(dir.file("one/mesh.ply"));
  EXPECT_NEAR(merged.accuracy_mean_m, together.accuracy_mean_m, 0.001);
  EXPECT_NEAR(merged.completeness, together.completeness, 0.002);

  // Each drive asks for the peak its own run predicts, whatever its place in the list.
  const BatchPlan plan = BatchPlan::load(dir.file("batch"));
  for (std::size_t i = 0; i < plan.drives().size(); ++i) {
    const std::string log = test::readText(dir.file("batch/logs/" + plan.drives()[i].name + ".log"));
    const std::size_t at = log.find("Memory: predicted peak ");
    ASSERT_NE(at, std::string::npos) << log;
    const double run_mb = std::stod(log.substr(at + std::string("Memory: predicted peak ").size()));
    EXPECT_NEAR(plan.predictedMb(i), run_mb, 0.05 * run_mb) << plan.drives()[i].name;
  }

  // Run again: nothing is redone (one attempt per drive in its times), the map stays.
  const auto mesh_time = fs::last_write_time(map + "/mesh.ply");
  const test::CommandResult again =
      test::runCommand(batchTool() + " -o " + dir.file("batch") + " -local 2 -merge_tasks 2" + common);
  ASSERT_EQ(again.exit_code, 0) << again.out << again.err;
  for (const char* name : {"a_from_start", "b_from_12m", "c_back_from_44m"})
    EXPECT_EQ(test::lineCount(dir.file(std::string("batch/logs/") + name + ".times")), 1u) << name;
  EXPECT_EQ(fs::last_write_time(map + "/mesh.ply"), mesh_time);

  // A changed request is not mistaken for done: other frames, another config.
  const BatchPlan done = BatchPlan::load(dir.file("batch"));
  std::vector<Drive> drives = done.drives();
  EXPECT_TRUE(done.driveDone(0));
  EXPECT_FALSE(BatchPlan(dir.file("batch"), drives, optionsFor(plainConfig(), "0:3")).driveDone(0));
  EXPECT_FALSE(BatchPlan(dir.file("batch"), drives, optionsFor(config())).driveDone(0));
}

/// A drive of the generic layout (the street's second drive, converted by msf_convert) is
/// predicted, run and merged as its KITTI layout is: the map of the local batch is the one process
/// map of the KITTI layouts.
TEST_F(BatchPlanTest, ADriveOfTheGenericLayoutMergesAsItsKittiLayout) {
  test::TempDir dir;
  fs::create_directory(dir.file("own"));
  const test::CommandResult convert = test::runCommand(test::binDir() + "/msf_convert '" + drives()[1] + "' " +
                                                       dir.file("own/b_from_12m"));
  ASSERT_EQ(convert.exit_code, 0) << convert.out << convert.err;
  const std::string settings = " -config '" + plainConfig() + "' -stream " + kStream;
  const test::CommandResult own = test::runCommand(batchTool() + " -o " + dir.file("batch") + " -local 2" + settings +
                                                   " '" + drives()[0] + "' " + dir.file("own/b_from_12m"));
  ASSERT_EQ(own.exit_code, 0) << own.out << own.err;
  EXPECT_NE(own.out.find("b_from_12m"), std::string::npos) << own.out;
  const test::CommandResult kitti = test::runCommand(batchTool() + " -o " + dir.file("one") + " -one_process" +
                                                     settings + " '" + drives()[0] + "' '" + drives()[1] + "'");
  ASSERT_EQ(kitti.exit_code, 0) << kitti.out << kitti.err;
  const test::StoreDifference d =
      test::compareStores(TsdfStore::open(dir.file("batch/map")), TsdfStore::open(dir.file("one")));
  EXPECT_TRUE(d.same_blocks);
  EXPECT_GT(d.observed, 50000u);
  EXPECT_LT(d.sdf, 1e-4) << "metres";
  EXPECT_LT(d.weight_relative, 1e-4);
}

TEST_F(BatchPlanTest, RefusesDrivesWithoutPosesAndForeignFolders) {
  test::TempDir dir;
  // A drive whose poses are not known before the run: its sequence without poses/00.txt.
  fs::create_directories(dir.file("no_poses/sequences"));
  fs::create_directory_symlink(fs::path(drives()[0]) / "sequences" / "00", dir.file("no_poses/sequences/00"));
  test::CommandResult r = test::runCommand(batchTool() + " -o " + dir.file("out") + " -local 1 -stream 120 " +
                                           dir.file("no_poses"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("has no poses"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("out/drives"))) << "nothing is written before the plan holds";

  fs::create_directories(dir.file("theirs"));
  std::ofstream(dir.file("theirs/thesis.tex")) << "mine";
  r = test::runCommand(batchTool() + " -o " + dir.file("theirs") + " -local 1 -stream 120 " + drives()[0]);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("thesis.tex"), std::string::npos) << r.err;
  EXPECT_EQ(test::countEntries(dir.file("theirs")), 1u);

  r = test::runCommand(batchTool() + " -o " + dir.file("out2") + " " + drives()[0]);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("-slurm"), std::string::npos) << r.err;
}

} // namespace
