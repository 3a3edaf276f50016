// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_batch: many drives, one map. Each drive reconstructed by msf_reconstruct -stream as a
// task of its own (a Slurm job array, or N local processes), their TSDF stores merged tile by
// tile into one map (docs/batch.md).
#include <msf/batch/batch_plan.h>
#include <msf/batch/batch_tasks.h>
#include <msf/batch/drive_list.h>
#include <msf/batch/drive_resources.h>
#include <msf/batch/local_runner.h>
#include <msf/batch/one_process_map.h>
#include <msf/batch/slurm_jobs.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/pipeline/run_report.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

/// What the command line sets beside the plan's options.
struct Settings {
  std::string out, list, run_task, reconstruct;
  bool slurm = false, wait = false, one_process = false;
  int local = 0;
  double timeout_s = 0;
  msf::SlurmOptions slurm_options;
};

/// This program, and msf_reconstruct beside it (the build's bin/ or the install's).
std::string selfPath() { return fs::canonical("/proc/self/exe").string(); }

std::string findReconstruct(const std::string& given) {
  if (!given.empty()) {
    if (!fs::is_regular_file(given) || ::access(given.c_str(), X_OK) != 0)
      throw msf::InvalidInputError("-reconstruct '" + given + "' is not an executable file");
    return fs::absolute(given).lexically_normal().string();
  }
  const fs::path beside = fs::path(selfPath()).parent_path() / "msf_reconstruct";
  if (!fs::is_regular_file(beside))
    throw msf::InvalidInputError("msf_reconstruct is not beside msf_batch ('" + beside.string() +
                                 "'): give its path with -reconstruct");
  return beside.string();
}

std::vector<msf::Drive> collectDrives(const msf::tool::Arguments& paths, const std::string& list) {
  std::vector<msf::Drive> drives;
  for (const std::string& p : paths)
    for (const msf::Drive& d : msf::findDrives(p))
      drives.push_back(d);
  if (!list.empty())
    for (const msf::Drive& d : msf::readDriveList(list))
      drives.push_back(d);
  if (drives.empty())
    throw msf::InvalidInputError("no drives: give datasets (a drive, or a root holding several) or -list FILE");
  msf::nameDrives(drives);
  return drives;
}

/// Predicts each drive's memory (the run's own model) and prints the plan.
void predictResources(msf::BatchPlan& plan) {
  // Each prediction grows this process; each drive's run starts from a new one.
  const double process_mb = msf::residentMemoryMb();
  print_info("%-28s %8s %14s %12s\n", "drive", "frames", "predicted MiB", "request MiB");
  for (std::size_t i = 0; i < plan.drives().size(); ++i) {
    const msf::DriveResources r =
        msf::predictDriveResources(plan.drives()[i], plan.pipelineConfig(), plan.options().frames, process_mb);
    plan.setResources(i, r.predicted_mb, r.request_mb);
    print_info("%-28s %8zu %14.0f %12zu%s\n", plan.drives()[i].name.c_str(), r.frames, r.predicted_mb, r.request_mb,
               plan.driveDone(i) ? "   done" : "");
  }
}

/// Three quarters of this machine's memory: what the local runner lets the drives' predictions fill.
double localMemoryMb() {
  return 0.75 * static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE)) /
         (1024.0 * 1024.0);
}

/// Says where the map is, or which drives are not done. Returns the exit code.
int report(const msf::BatchPlan& plan) {
  if (plan.mapDone()) {
    print_info("Map: ");
    print_value("%s/mesh.ply", plan.mapDir().c_str());
    print_info(" (summary.json beside it)\n");
    return 0;
  }
  for (std::size_t i = 0; i < plan.drives().size(); ++i)
    if (!plan.driveDone(i))
      print_error("drive %s is not done: see %s\n", plan.drives()[i].name.c_str(), plan.driveLog(i).c_str());
  print_error("msf_batch: error: the map is not done (tasks' logs: %s)\n", plan.logDir().c_str());
  return 1;
}

/// The merge starts from nothing unless the map is done: a cancelled round's shares are not reused.
void restartMerge(const msf::BatchPlan& plan) {
  if (plan.mapDone())
    return;
  plan.clearMapDone();
  std::error_code e;
  fs::remove_all(plan.mergeDir(), e);
}

/// Submits what is not done and prints the job ids ("Submitted ..."); none when the map is done.
msf::SlurmSubmission submitRound(const msf::BatchPlan& plan, const Settings& s) {
  restartMerge(plan);
  const msf::SlurmSubmission jobs = msf::submitToSlurm(plan, s.slurm_options);
  if (jobs.all().empty()) {
    print_info("Nothing to submit: the map is done for these drives\n");
    return jobs;
  }
  std::string ids;
  for (const std::string& id : jobs.all())
    ids += (ids.empty() ? "" : " ") + id;
  print_highlight("Submitted ");
  print_value("%s", ids.c_str());
  print_info(" (drives, merge, mesh, finish; scripts in %s)\n", plan.jobDir().c_str());
  std::fflush(stdout); // the ids, for whoever reads a log of -wait while it waits
  return jobs;
}

/// -wait: submits, waits for the jobs to end, and submits again what is not done, up to
/// -max_attempts rounds: a task whose job ends without its script (scancel, or the script
/// killed with it) is not requeued by Slurm nor by the script, and its dependents are cancelled.
int submitAndWait(const msf::BatchPlan& plan, const Settings& s) {
  const auto start = std::chrono::steady_clock::now();
  for (int round = 1; round <= plan.options().max_attempts && !plan.mapDone(); ++round) {
    if (round > 1)
      print_warn("The jobs ended and the map is not done: submitting what is not done again (round %d of %d)\n",
                 round, plan.options().max_attempts);
    const msf::SlurmSubmission jobs = submitRound(plan, s);
    const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double left = s.timeout_s > 0 ? std::max(s.timeout_s - spent, 1.0) : 0.0; // 0: no bound
    if (!msf::waitForSlurm(jobs, left))
      throw msf::InvalidInputError("-timeout: the jobs are still queued or running after " +
                                   std::to_string(s.timeout_s) + " s (ids in " + plan.jobDir() + "/submitted.txt)");
  }
  return report(plan);
}

int planAndRun(const Settings& s, const msf::tool::Arguments& paths, msf::BatchOptions options) {
  const int modes = (s.slurm ? 1 : 0) + (s.local > 0 ? 1 : 0) + (s.one_process ? 1 : 0);
  if (modes != 1)
    throw msf::InvalidInputError("say where the tasks run, once: -slurm (jobs on a Slurm cluster), -local N (N at a "
                                 "time on this machine) or -one_process (all frames in this process)");
  if (s.wait && !s.slurm)
    throw msf::InvalidInputError("-wait is for -slurm (-local and -one_process end when the map is made)");
  options.batch = selfPath();
  options.reconstruct = findReconstruct(s.reconstruct);
  if (!options.config.empty())
    options.config = fs::absolute(options.config).lexically_normal().string();
  msf::BatchPlan plan(s.out, collectDrives(paths, s.list), options);
  if (s.one_process) {
    pcl::console::TicToc tt;
    tt.tic();
    print_highlight("Integrating %zu drives in one process into ", plan.drives().size());
    print_value("%s\n", s.out.c_str());
    const std::size_t triangles = msf::reconstructInOneProcess(plan, s.out);
    msf::tool::printDone(tt.toc(), triangles, "triangles");
    return 0;
  }
  plan.requireRoot(); // a folder of someone else's is refused before the drives are read
  predictResources(plan);
  plan.save();
  if (s.local > 0) {
    restartMerge(plan);
    print_highlight("Running the batch here, %d task%s at a time\n", s.local, s.local > 1 ? "s" : "");
    msf::LocalRunner(plan, s.local, localMemoryMb()).run();
    return report(plan);
  }
  return s.wait ? submitAndWait(plan, s) : (submitRound(plan, s), 0);
}

} // namespace

int main(int argc, char** argv) {
  Settings s;
  msf::BatchOptions options;
  msf::tool::CommandLine cli(
      "msf_batch", "-o OUT (-slurm | -local N | -one_process) [DATASET ...] [-list FILE] [options]",
      "Reconstructs many drives into one map. Each drive (a KITTI odometry sequence, a KITTI raw drive, a synthetic "
      "street, a folder of the generic layout or a ROS bag, as msf_reconstruct reads them; a root gives all it holds) is a task of its own: msf_reconstruct DRIVE -stream R -o "
      "OUT/drives/NAME, with its log in OUT/logs/NAME.log; then the drives' TSDF stores are merged tile by tile (the "
      "TSDF's weighted mean per voxel) by merge_tasks tasks, meshed by as many, and OUT/map (mesh.ply, tsdf/, tiles/, "
      "summary.json) is committed. The drives' poses must share a world. Run again, it does only what is not done: a "
      "drive whose folder is committed for the same request (dataset, frames, poses, options, config) is never "
      "redone; a task that fails starts again from nothing, up to -max_attempts.");
  cli.value("-o", "OUT", s.out, "the batch's output root (absent, empty, or an earlier batch's)")
      .value("-list", "FILE", s.list, "drives, one a line: DATASET [POSES] (poses in the shared world)")
      .flag("-slurm", s.slurm,
            "submit the tasks to Slurm (sbatch): an array of drives per memory request, then the merge, mesh and "
            "finish jobs, each after the one before (afterok)")
      .value("-local", "N", s.local, "run the same tasks on this machine, N at a time, no scheduler needed")
      .flag("-one_process", s.one_process,
            "integrate every drive's frames into one volume in this process into OUT (the map the merge equals for "
            "a plain weighted mean; for a few small drives)")
      .flag("-wait", s.wait,
            "with -slurm: wait until the jobs end, submit again what a cancelled or killed job left undone "
            "(up to -max_attempts rounds), then say whether the map is done")
      .value("-timeout", "S", s.timeout_s, "with -wait: give up after S seconds (default {default}: no bound)")
      .value("-config", "FILE", options.config, "YAML configuration of every drive's msf_reconstruct")
      .value("-frames", "a:b", options.frames, "each drive's frame range (default {default})")
      .value("-stream", "R", options.stream_m,
             "each drive's streaming.active_radius_m (default {default}; at least the integrator's reach plus a tile)")
      .value("-voxel", "V", options.voxel_m, "voxel size in metres (default: the config's)")
      .value("-cpus", "C", options.cpus, "CPUs of a drive's task (default {default})")
      .value("-merge_tasks", "M", options.merge_tasks,
             "tasks that merge, and then mesh, shares of the tiles side by side (default {default})")
      .value("-max_attempts", "A", options.max_attempts,
             "attempts of a task that fails, each from nothing (default {default})")
      .value("-partition", "P", s.slurm_options.partition, "with -slurm: the partition (default: the cluster's)")
      .value("-time", "MIN", s.slurm_options.time_min, "with -slurm: each task's time limit in minutes")
      .value("-reconstruct", "PATH", s.reconstruct, "msf_reconstruct (default: the one beside msf_batch)")
      .value("-run", "TASK", s.run_task,
             "run one task of the batch in OUT (drive:N, merge:N, mesh:N, finish): what the jobs and the local "
             "runner call")
      .note("Memory: each drive asks for its predicted peak (msf_reconstruct's own model, Reconstructor::predictMemory) "
            "with a margin of 20 %, rounded up to 256 MiB; -local runs no more drives at once than fit in 3/4 of "
            "this machine's memory. See docs/batch.md and docs/scale.md.");
  return cli.run(argc, argv, 0, [&](const msf::tool::Arguments& paths) {
    if (s.out.empty())
      throw msf::InvalidInputError("no output root: give -o OUT");
    if (!s.run_task.empty()) {
      if (!paths.empty() || s.slurm || s.local > 0 || s.one_process || !s.list.empty())
        throw msf::InvalidInputError("-run TASK takes only -o OUT: the plan in OUT says the rest");
      const msf::BatchTask task = msf::BatchTask::parse(s.run_task);
      return msf::runBatchTask(msf::BatchPlan::load(s.out), task);
    }
    return planAndRun(s, paths, options);
  });
}
