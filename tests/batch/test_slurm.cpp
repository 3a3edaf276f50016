// The batch on a real Slurm cluster: the one CI starts (scripts/slurm_local.sh, SLURM_CONF), or
// one this test starts on localhost and stops. It skips only where Slurm cannot start here,
// and under CI=true that is a failure.
#include "batch_fixture.h"

#include <msf/batch/subprocess.h>
#include <msf/reconstruction/tsdf_store.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
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

/// Waits until none of `ids` is queued, at most `seconds`. False when the bound ran out.
bool waitForJobs(const std::vector<std::string>& ids, double seconds) {
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds) {
    const CommandOutput r = captureCommand({"squeue", "-h", "-o", "%A"});
    bool queued = false;
    for (const std::string& id : ids)
      queued = queued || (r.status == 0 && std::regex_search(r.out, std::regex("(^|\n)" + id + "(\n|$)")));
    if (r.status == 0 && !queued)
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  return false;
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

/// Three drives as a job array on the cluster and merged; then again with a drive's
/// msf_reconstruct killed (kill -9) in the middle: the task is requeued, starts the drive
/// again from nothing, and the map is the undisturbed run's, byte for byte.
TEST_F(SlurmBatch, ThreeDrivesOnTheClusterAndAKilledTaskRequeued) {
  const SlurmCluster cluster;
  if (!cluster.whyNot().empty()) {
    if (test::underCi())
      FAIL() << cluster.whyNot() << "; CI=true requires a Slurm cluster (.ci/run starts one)";
    GTEST_SKIP() << cluster.whyNot();
  }
  test::TempDir dir;
  const std::string common = " -slurm -cpus 1 -merge_tasks 2 -config '" + config() + "' -stream " + kStream +
                             driveArguments();
  const test::CommandResult run =
      test::runCommand(batchTool() + " -o " + dir.file("s1") + common + " -wait -timeout 900");
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const std::string map = dir.file("s1/map");
  ASSERT_TRUE(test::fileExists(map + "/mesh.ply"));
  expectBetterThanEachDrive(dir.file("s1"), test::StreetTruth(drives()));

  // The same batch with one drive to make again, and its run killed once it is under way. The
  // others are done: they are not run again.
  fs::copy(dir.file("s1"), dir.file("s2"), fs::copy_options::recursive);
  fs::remove(dir.file("s2/state/drive_b_from_12m.done"));
  fs::remove(dir.file("s2/state/map.done"));
  const std::string log = dir.file("s2/logs/b_from_12m.log");
  const std::size_t logged = test::readText(log).size(); // the first run's attempt
  const test::CommandResult submitted = test::runCommand(batchTool() + " -o " + dir.file("s2") + common);
  ASSERT_EQ(submitted.exit_code, 0) << submitted.out << submitted.err;
  const std::vector<std::string> jobs = submittedJobs(submitted.out);
  ASSERT_EQ(jobs.size(), 4u) << submitted.out; // the drive (an array of one), merge, mesh, finish
  const std::string victim = dir.file("s2/drives/b_from_12m");
  pid_t pid = -1;
  for (int k = 0; k < 1200 && pid < 0; ++k) {
    if (test::readText(log).find("frame 000001", logged) != std::string::npos)
      pid = processWith(victim);
    if (pid < 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_GT(pid, 0) << "the drive's run was never seen under way: " << test::readText(log);
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  ASSERT_TRUE(waitForJobs(jobs, 900)) << "the jobs did not end within 15 minutes";
  ASSERT_TRUE(test::fileExists(dir.file("s2/map/mesh.ply"))) << test::readText(log);
  // Two more attempts: the killed one (128 + 9) and the one after the requeue; none of the others.
  const std::string times = test::readText(dir.file("s2/logs/b_from_12m.times"));
  EXPECT_EQ(test::lineCount(dir.file("s2/logs/b_from_12m.times")), 3u) << times;
  EXPECT_NE(times.find(" 137\n"), std::string::npos) << times;
  EXPECT_EQ(test::lineCount(dir.file("s2/logs/a_from_start.times")), 1u);
  EXPECT_EQ(test::lineCount(dir.file("s2/logs/c_back_from_44m.times")), 1u);
  EXPECT_NE(test::readText(dir.file("s2/logs/slurm_drive_1.out")).find("requeued"), std::string::npos);
  EXPECT_TRUE(sameMap(map, dir.file("s2/map")));
}

} // namespace
