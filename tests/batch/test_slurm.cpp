// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The batch on a real Slurm cluster: the one CI starts (scripts/slurm_local.sh, SLURM_CONF), or
// one this test starts on localhost and stops. It skips only where Slurm cannot start here,
// and under CI=true that is a failure.
#include "batch_fixture.h"

#include <msf/batch/subprocess.h>
#include <msf/reconstruction/tsdf_store.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <regex>
#include <set>
#include <signal.h>
#include <thread>

using namespace msf;
namespace fs = std::filesystem;

namespace {

std::string batchTool() { return test::binDir() + "/msf_batch"; }

bool clusterTakesJobs() {
  const CommandOutput r = captureCommand({"sinfo", "-h", "-N", "-o", "%t"});
  return r.status == 0 && std::regex_search(r.out, std::regex("^(idle|mix|alloc)", std::regex::multiline));
}

/// The cluster of SLURM_CONF when it takes jobs, else one started here for this test's process.
class SlurmCluster {
public:
  SlurmCluster() {
    if (std::getenv("SLURM_CONF") && clusterTakesJobs())
      return;
    state_ = dir_.file("slurm");
    const std::string script = test::sourceDir() + "/scripts/slurm_local.sh";
    // A port of its own, so that it does not meet a cluster another process runs here.
    const std::string port = std::to_string(17000 + ::getpid() % 2000 * 2);
    const test::CommandResult r = test::runCommand("MSF_SLURM_PORT=" + port + " bash " + script + " start " + state_);
    if (r.exit_code != 0) {
      why_not_ = "Slurm cannot start here (scripts/slurm_local.sh start: " + r.err + ")";
      return;
    }
    ::setenv("SLURM_CONF", (state_ + "/slurm.conf").c_str(), 1);
    started_ = true;
  }
  ~SlurmCluster() {
    if (started_)
      test::runCommand("bash " + test::sourceDir() + "/scripts/slurm_local.sh stop " + state_);
  }
  const std::string& whyNot() const { return why_not_; }

private:
  test::TempDir dir_;
  std::string state_, why_not_;
  bool started_ = false;
};

/// The job ids msf_batch printed ("Submitted 12 13 14 15").
std::vector<std::string> submittedJobs(const std::string& out) {
  std::smatch m;
  std::vector<std::string> ids;
  if (std::regex_search(out, m, std::regex("Submitted ([0-9 ]+)"))) {
    std::stringstream ss(m[1].str());
    for (std::string id; ss >> id;)
      ids.push_back(id);
  }
  return ids;
}

/// The memory requests (MiB) of the drives msf_batch's table lists as not done.
std::set<std::string> requestsToRun(const std::string& out) {
  std::set<std::string> requests;
  std::stringstream lines(out);
  const std::regex row(R"(^\S+\s+[0-9]+\s+[0-9]+\s+([0-9]+)\s*$)");
  std::smatch m;
  for (std::string line; std::getline(lines, line);)
    if (std::regex_match(line, m, row))
      requests.insert(m[1].str());
  return requests;
}

/// The process whose command line holds `needle` (this test's own msf_reconstruct), or -1.
pid_t processWith(const std::string& needle) {
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos)
      continue;
    std::string cmdline = test::readText(e.path().string() + "/cmdline");
    for (char& c : cmdline)
      if (c == '\0')
        c = ' ';
    if (cmdline.find("msf_reconstruct") != std::string::npos && cmdline.find(needle) != std::string::npos)
      return static_cast<pid_t>(std::stol(name));
  }
  return -1;
}

/// When the test ends, however it ends: stops the msf_batch it started if it still runs, and
/// cancels the jobs its batches submitted (a failed assertion would leave them queued, to fail
/// again and again once the test's folder is gone).
class JobsOfTheTest {
public:
  explicit JobsOfTheTest(std::vector<std::string> outs) : outs_(std::move(outs)) {}
  JobsOfTheTest(const JobsOfTheTest&) = delete;
  JobsOfTheTest& operator=(const JobsOfTheTest&) = delete;
  /// Starts msf_batch with `argv`, its output appended to `log`.
  Subprocess& start(const std::vector<std::string>& argv, const std::string& log) {
    batch_ = std::make_unique<Subprocess>(argv, log);
    return *batch_;
  }
  ~JobsOfTheTest() {
    int status = 0;
    if (batch_ && !batch_->finished(status))
      ::kill(batch_->pid(), SIGTERM);
    batch_.reset();
    std::vector<std::string> cancel = {"scancel"};
    for (const std::string& out : outs_) {
      std::stringstream ids(test::readText(out + "/jobs/submitted.txt"));
      for (std::string id; ids >> id;)
        cancel.push_back(id);
    }
    if (cancel.size() > 1)
      captureCommand(cancel); // finished jobs are refused, and that is all
  }

private:
  std::vector<std::string> outs_;
  std::unique_ptr<Subprocess> batch_;
};

/// Every file of the map's store and its mesh, byte for byte.
bool sameMap(const std::string& a, const std::string& b) {
  std::vector<std::string> files = {"mesh.ply", "tsdf/index.txt"};
  const TsdfStore store = TsdfStore::open(a);
  for (const GridIndex& t : store.tiles())
    files.push_back("tsdf/" + TsdfStore::tileName(t) + ".blk");
  for (const std::string& f : files)
    if (test::readText(a + "/" + f) != test::readText(b + "/" + f) || test::readText(a + "/" + f).empty()) {
      ADD_FAILURE() << f << " differs";
      return false;
    }
  return true;
}

class SlurmBatch : public test::BatchDrives {};

/// Three drives as a job array on the cluster and merged; then two of them again, one drive's
/// msf_reconstruct killed (kill -9) and the other's task cancelled (scancel) in the middle: each
/// is made again from nothing, and the map is the undisturbed run's, byte for byte.
TEST_F(SlurmBatch, ThreeDrivesOnTheClusterAndKilledOrCancelledTasksMadeAgain) {
  const SlurmCluster cluster;
  if (!cluster.whyNot().empty()) {
    if (test::underCi())
      FAIL() << cluster.whyNot() << "; CI=true requires a Slurm cluster (.ci/run starts one)";
    GTEST_SKIP() << cluster.whyNot();
  }
  test::TempDir dir;
  JobsOfTheTest jobs_of_the_test({dir.file("s1"), dir.file("s2")});
  // The batch into `out` on the cluster, waiting for its map.
  const auto batchArguments = [](const std::string& out) {
    std::vector<std::string> argv = {batchTool(), "-o", out, "-slurm", "-cpus", "1", "-merge_tasks", "2", "-config",
                                     config(), "-stream", kStream, "-wait", "-timeout", "900"};
    argv.insert(argv.end(), drives().begin(), drives().end());
    return argv;
  };
  const test::CommandResult run = test::runCommand(shellQuote(batchArguments(dir.file("s1"))));
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const std::string map = dir.file("s1/map");
  ASSERT_TRUE(test::fileExists(map + "/mesh.ply"));
  expectBetterThanEachDrive(dir.file("s1"), test::StreetTruth(drives()));

  // The same batch with two drives to make again, run with -wait: one drive's msf_reconstruct
  // killed (kill -9) under way, whose task the job script requeues; the other's task cancelled
  // (scancel), which ends its job and cancels the merge: msf_batch submits it again. The first
  // drive is done: it is not run again.
  fs::copy(dir.file("s1"), dir.file("s2"), fs::copy_options::recursive);
  for (const char* stamp : {"drive_b_from_12m.done", "drive_c_back_from_44m.done", "map.done"})
    fs::remove(dir.file("s2/state/") + stamp);
  const std::string killed_log = dir.file("s2/logs/b_from_12m.log"), cancelled_log = dir.file("s2/logs/c_back_from_44m.log");
  const std::size_t killed_from = test::readText(killed_log).size(), cancelled_from = test::readText(cancelled_log).size();
  const std::string batch_log = dir.file("batch.log");
  Subprocess& batch = jobs_of_the_test.start(batchArguments(dir.file("s2")), batch_log);
  pid_t victim = -1;
  bool cancelled = false;
  for (int k = 0; k < 1200 && (victim < 0 || !cancelled); ++k) {
    if (victim < 0 && test::readText(killed_log).find("frame 000000", killed_from) != std::string::npos &&
        (victim = processWith(dir.file("s2/drives/b_from_12m"))) > 0) {
      ASSERT_EQ(::kill(victim, SIGKILL), 0);
    }
    if (!cancelled && test::readText(cancelled_log).find("frame 000000", cancelled_from) != std::string::npos) {
      // The task's id from its attempt's header: msf_batch may still be submitting the stages after it.
      std::smatch task;
      const std::string attempt = test::readText(cancelled_log).substr(cancelled_from);
      ASSERT_TRUE(std::regex_search(attempt, task, std::regex("Slurm job ([0-9]+_[0-9]+)"))) << attempt;
      const CommandOutput r = captureCommand({"scancel", task[1].str()});
      ASSERT_EQ(r.status, 0) << r.err;
      cancelled = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_GT(victim, 0) << "the drive's run was never seen under way: " << test::readText(killed_log);
  ASSERT_TRUE(cancelled) << "the drive's run was never seen under way: " << test::readText(cancelled_log);
  ASSERT_EQ(batch.wait(), 0) << test::readText(batch_log);
  // The two drives left (one array per memory request: their predictions may round apart), merge,
  // mesh, finish.
  EXPECT_EQ(submittedJobs(test::readText(batch_log)).size(), 3u + requestsToRun(test::readText(batch_log)).size())
      << test::readText(batch_log);
  EXPECT_NE(test::readText(batch_log).find("submitting what is not done again (round 2 of "), std::string::npos)
      << test::readText(batch_log);
  // The killed drive: two more attempts, the killed one (128 + 9) and the one after the requeue.
  const std::string times = test::readText(dir.file("s2/logs/b_from_12m.times"));
  EXPECT_EQ(test::lineCount(dir.file("s2/logs/b_from_12m.times")), 3u) << times;
  EXPECT_NE(times.find(" 137\n"), std::string::npos) << times;
  EXPECT_NE(test::readText(dir.file("s2/logs/slurm_drive_1.out")).find("requeued"), std::string::npos);
  // The cancelled drive made again to its end; the done one never run again.
  const std::string cancelled_times = test::readText(dir.file("s2/logs/c_back_from_44m.times"));
  EXPECT_GE(test::lineCount(dir.file("s2/logs/c_back_from_44m.times")), 2u) << cancelled_times;
  EXPECT_EQ(cancelled_times.substr(cancelled_times.rfind(' ')), " 0\n") << cancelled_times;
  EXPECT_EQ(test::lineCount(dir.file("s2/logs/a_from_start.times")), 1u);
  EXPECT_TRUE(sameMap(map, dir.file("s2/map")));
}

} // namespace
