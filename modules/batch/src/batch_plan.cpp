// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/batch_plan.h>
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace msf {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPlanTag = "msfusion-batch 1";
// What a batch writes in OUT (and the staging folders and temporaries of its files).
const std::set<std::string> kBatchEntries = {"plan.txt", "drives", "state", "logs", "merge", "map", "jobs"};

void writeText(const std::string& path, const std::string& text) {
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out.flush())
      throw IOError("cannot write '" + path + "': disk full?");
  });
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Every entry of OUT is one a batch writes; throws IOError naming the first that is not.
void requireBatchRoot(const fs::path& out) {
  std::error_code e;
  if (!fs::exists(out, e))
    return;
  if (!fs::is_directory(out, e))
    throw IOError("batch output '" + out.string() + "' exists and is not a folder");
  const bool is_batch = fs::is_regular_file(out / BatchPlan::planName(), e);
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    const bool ours = kBatchEntries.count(name) || name.rfind(".map.", 0) == 0 || name.rfind(".plan.", 0) == 0;
    if (!is_batch || !ours)
      throw IOError("batch output '" + out.string() + "' holds '" + name + "', which " +
                    (is_batch ? "a batch does not write" : "is not a batch's (no plan.txt)") +
                    ": give an absent or empty folder, or an earlier output of msf_batch");
  }
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

} // namespace

std::string fileDigest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw IOError("cannot read '" + path + "'");
  std::uint64_t h = 1469598103934665603ULL;
  char buffer[65536];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i)
      h = (h ^ static_cast<unsigned char>(buffer[i])) * 1099511628211ULL;
    if (!in)
      break;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

const char* BatchPlan::planName() { return "plan.txt"; }

BatchPlan::BatchPlan(std::string out, std::vector<Drive> drives, BatchOptions options)
    : out_(fs::absolute(out).lexically_normal().string()), drives_(std::move(drives)), options_(std::move(options)) {
  if (!out_.empty() && out_.back() == '/')
    out_.pop_back();
  if (drives_.empty())
    throw InvalidInputError("a batch needs at least one drive");
  if (options_.cpus < 1 || options_.merge_tasks < 1 || options_.max_attempts < 1)
    throw InvalidInputError("-cpus, -merge_tasks and -max_attempts must be at least 1");
  config_ = PipelineConfig::load(options_.config);
  if (options_.voxel_m > 0)
    config_.volume.voxel_size_m = options_.voxel_m;
  config_.streaming.active_radius_m = options_.stream_m;
  config_.validate();
  if (!config_.streaming.enabled())
    throw InvalidInputError("-stream must be > 0: a batch merges the drives' TSDF stores, which a streamed run writes");
  config_digest_ = options_.config.empty() ? "-" : fileDigest(options_.config);
  for (const Drive& d : drives_)
    poses_digests_.push_back(d.poses.empty() ? "-" : fileDigest(d.poses));
  predicted_mb_.assign(drives_.size(), 0.0);
  request_mb_.assign(drives_.size(), 0);
}

void BatchPlan::setResources(std::size_t drive, double predicted_mb, std::size_t request_mb) {
  predicted_mb_.at(drive) = predicted_mb;
  request_mb_.at(drive) = request_mb;
}

void BatchPlan::requireRoot() const { requireBatchRoot(out_); }

void BatchPlan::save() const {
  requireBatchRoot(out_);
  ensureOutputDirectory(out_);
  for (const char* sub : {"drives", "state", "logs", "jobs"})
    fs::create_directories(fs::path(out_) / sub);
  std::ostringstream ss;
  ss << kPlanTag << "\nbatch " << options_.batch << "\nreconstruct " << options_.reconstruct << "\nconfig "
     << (options_.config.empty() ? "-" : options_.config) << "\nframes " << options_.frames << "\nstream_m "
     << number(options_.stream_m) << "\nvoxel_m " << number(options_.voxel_m) << "\ncpus " << options_.cpus
     << "\nmerge_tasks " << options_.merge_tasks << "\nmax_attempts " << options_.max_attempts << "\ndrives "
     << drives_.size() << "\n";
  for (std::size_t i = 0; i < drives_.size(); ++i)
    ss << drives_[i].name << "\t" << drives_[i].dataset << "\t" << (drives_[i].poses.empty() ? "-" : drives_[i].poses)
       << "\t" << number(predicted_mb_[i]) << "\t" << request_mb_[i] << "\n";
  writeText((fs::path(out_) / planName()).string(), ss.str());
}

BatchPlan BatchPlan::load(const std::string& out) {
  const std::string path = (fs::path(out) / planName()).string();
  requireFile(path, "batch plan");
  std::ifstream in(path);
  const auto fail = [&](const std::string& what) -> IOError {
    return IOError("batch plan '" + path + "' " + what + ": write it again with msf_batch");
  };
  std::string line;
  if (!std::getline(in, line) || line != kPlanTag)
    throw fail("does not start with '" + std::string(kPlanTag) + "'");
  std::map<std::string, std::string> values;
  for (const char* key : {"batch", "reconstruct", "config", "frames", "stream_m", "voxel_m", "cpus", "merge_tasks",
                          "max_attempts", "drives"}) {
    if (!std::getline(in, line) || line.rfind(std::string(key) + " ", 0) != 0)
      throw fail("lacks '" + std::string(key) + "' where line '" + line + "' is");
    values[key] = line.substr(std::string(key).size() + 1);
  }
  BatchOptions o;
  o.batch = values["batch"];
  o.reconstruct = values["reconstruct"];
  o.config = values["config"] == "-" ? "" : values["config"];
  o.frames = values["frames"];
  try {
    o.stream_m = std::stod(values["stream_m"]);
    o.voxel_m = std::stod(values["voxel_m"]);
    o.cpus = std::stoi(values["cpus"]);
    o.merge_tasks = std::stoi(values["merge_tasks"]);
    o.max_attempts = std::stoi(values["max_attempts"]);
  } catch (const std::exception&) {
    throw fail("has a number that is not one");
  }
  std::size_t count = 0;
  try {
    count = std::stoul(values["drives"]);
  } catch (const std::exception&) {
    throw fail("has a drive count that is not a number");
  }
  std::vector<Drive> drives;
  std::vector<std::pair<double, std::size_t>> resources;
  for (std::size_t i = 0; i < count; ++i) {
    std::vector<std::string> f;
    if (!std::getline(in, line))
      throw fail("ends after " + std::to_string(i) + " of its " + std::to_string(count) + " drives");
    std::stringstream ss(line);
    for (std::string field; std::getline(ss, field, '\t');)
      f.push_back(field);
    if (f.size() != 5)
      throw fail("has a drive line that is not 'NAME DATASET POSES PREDICTED_MB REQUEST_MB': '" + line + "'");
    drives.push_back({f[0], f[1], f[2] == "-" ? "" : f[2]});
    try {
      resources.emplace_back(std::stod(f[3]), std::stoul(f[4]));
    } catch (const std::exception&) {
      throw fail("has a drive line whose memory is not a number: '" + line + "'");
    }
  }
  BatchPlan plan(out, drives, o);
  for (std::size_t i = 0; i < count; ++i)
    plan.setResources(i, resources[i].first, resources[i].second);
  return plan;
}

std::string BatchPlan::driveDir(std::size_t drive) const { return out_ + "/drives/" + drives_.at(drive).name; }
std::string BatchPlan::driveLog(std::size_t drive) const { return out_ + "/logs/" + drives_.at(drive).name + ".log"; }
std::string BatchPlan::mergeDir() const { return out_ + "/merge"; }
std::string BatchPlan::mapDir() const { return out_ + "/map"; }
std::string BatchPlan::logDir() const { return out_ + "/logs"; }
std::string BatchPlan::jobDir() const { return out_ + "/jobs"; }
std::string BatchPlan::statePath(const std::string& name) const { return out_ + "/state/" + name + ".done"; }

std::vector<std::string> BatchPlan::reconstructCommand(std::size_t i) const {
  const Drive& d = drives_.at(i);
  std::vector<std::string> argv = {options_.reconstruct, d.dataset, "-o", driveDir(i), "-frames", options_.frames,
                                   "-stream", number(options_.stream_m), "-panels", "0"};
  if (!options_.config.empty())
    argv.insert(argv.end(), {"-config", options_.config});
  if (options_.voxel_m > 0)
    argv.insert(argv.end(), {"-voxel", number(options_.voxel_m)});
  if (!d.poses.empty())
    argv.insert(argv.end(), {"-poses", d.poses});
  return argv;
}

std::string BatchPlan::request(std::size_t i) const {
  const Drive& d = drives_.at(i);
  std::ostringstream ss;
  ss << "msfusion-batch-drive 1\ndataset " << d.dataset << "\nposes " << (d.poses.empty() ? "dataset" : d.poses)
     << " " << poses_digests_.at(i) << "\nconfig " << (options_.config.empty() ? "-" : options_.config) << " "
     << config_digest_ << "\nframes " << options_.frames << "\nstream_m " << number(options_.stream_m)
     << "\nvoxel_m " << number(options_.voxel_m) << "\nreconstruct " << options_.reconstruct << "\n";
  return ss.str();
}

bool BatchPlan::stampMatches(const std::string& name, const std::string& request) const {
  std::error_code e;
  return fs::is_regular_file(statePath(name), e) && readText(statePath(name)) == request;
}

void BatchPlan::writeStamp(const std::string& name, const std::string& request) const {
  fs::create_directories(fs::path(out_) / "state");
  writeText(statePath(name), request);
}

bool BatchPlan::driveDone(std::size_t i) const {
  std::error_code e;
  const fs::path dir = driveDir(i);
  return fs::is_regular_file(dir / OutputFolder::manifestName(), e) && fs::is_regular_file(dir / "summary.json", e) &&
         fs::is_regular_file(dir / "tsdf" / "index.txt", e) && stampMatches("drive_" + drives_.at(i).name, request(i));
}

void BatchPlan::markDriveDone(std::size_t i) const { writeStamp("drive_" + drives_.at(i).name, request(i)); }

void BatchPlan::clearDriveDone(std::size_t i) const {
  std::error_code e;
  fs::remove(statePath("drive_" + drives_.at(i).name), e);
}

std::string BatchPlan::mapRequest() const {
  std::ostringstream ss;
  ss << "msfusion-batch-map 1\nmerge_tasks " << options_.merge_tasks << "\n";
  for (std::size_t i = 0; i < drives_.size(); ++i)
    ss << "drive " << drives_[i].name << "\n" << request(i);
  return ss.str();
}

bool BatchPlan::mapDone() const {
  std::error_code e;
  return fs::is_regular_file(fs::path(mapDir()) / OutputFolder::manifestName(), e) && stampMatches("map", mapRequest());
}

void BatchPlan::markMapDone() const { writeStamp("map", mapRequest()); }

void BatchPlan::clearMapDone() const {
  std::error_code e;
  fs::remove(statePath("map"), e);
}

} // namespace msf
