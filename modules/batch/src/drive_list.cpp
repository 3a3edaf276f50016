// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/drive_list.h>
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/datasets/open_dataset.h>
#include <msf/io/folder_source.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace msf {

namespace fs = std::filesystem;

namespace {

bool isDir(const fs::path& p) {
  std::error_code e;
  return fs::is_directory(p, e);
}
bool isFile(const fs::path& p) {
  std::error_code e;
  return fs::is_regular_file(p, e);
}

/// The layouts openDataset reads, by their files alone (no calibration or poses read here).
bool isOdometrySequence(const fs::path& p) { return isFile(p / "calib.txt") && isDir(p / "image_0"); }
bool isRawDrive(const fs::path& p) {
  return isDir(p / "image_00" / "data") && isFile(p.parent_path() / "calib_cam_to_cam.txt");
}
bool isOwnFolder(const fs::path& p) { return FolderSource::looksLikeOne(p.string()); }
bool isBag(const fs::path& p) { return isFile(p) && isRosBag(p.string()); }

/// What the drives' errors say a drive may be.
const char* const kDriveLayouts = "a KITTI odometry sequence, a KITTI raw drive, a folder of the generic layout "
                                  "(left/, right/, lidar/, rig.yaml), a ROS bag or a synthetic street";

/// The drive `p` is: itself (a sequence, a folder of the generic layout or a bag), or the one
/// sequence of a root holding sequences/NN; empty when it is none.
fs::path sequenceOf(const fs::path& p) {
  if (isOdometrySequence(p) || isRawDrive(p) || isOwnFolder(p) || isBag(p))
    return p;
  std::vector<fs::path> found;
  if (isDir(p / "sequences"))
    for (const auto& e : fs::directory_iterator(p / "sequences"))
      if (isOdometrySequence(e.path()))
        found.push_back(e.path());
  return found.size() == 1 ? found.front() : fs::path();
}

fs::path normal(const std::string& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  return p.filename().empty() ? p.parent_path() : p;
}

/// The ROS bags directly in `p`, by their first bytes, sorted.
std::vector<fs::path> bagsIn(const fs::path& p) {
  std::vector<fs::path> out;
  if (isDir(p))
    for (const auto& e : fs::directory_iterator(p))
      if (isBag(e.path()))
        out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<fs::path> subfolders(const fs::path& p) {
  std::vector<fs::path> out;
  if (isDir(p))
    for (const auto& e : fs::directory_iterator(p))
      if (e.is_directory())
        out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

} // namespace

std::vector<Drive> findDrives(const std::string& path) {
  const fs::path root = normal(path);
  if (isFile(root) && !isBag(root))
    throw IOError("dataset '" + path + "' is a file and not a ROS bag (whose first bytes are '#ROSBAG V'): " +
                  "a drive is " + kDriveLayouts);
  if (!isBag(root))
    requireDirectory(path, "dataset");
  std::vector<fs::path> found;
  if (const fs::path one = sequenceOf(root); !one.empty()) {
    found.push_back(one);
  } else {
    for (const fs::path& p : subfolders(root / "sequences"))
      if (isOdometrySequence(p))
        found.push_back(p);
    for (const fs::path& bag : bagsIn(root))
      found.push_back(bag);
    for (const fs::path& level1 : subfolders(root)) {
      if (const fs::path inside = sequenceOf(level1); !inside.empty())
        found.push_back(inside);
      else
        for (const fs::path& level2 : subfolders(level1))
          if (isRawDrive(level2))
            found.push_back(level2);
    }
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  if (found.empty())
    throw IOError("dataset '" + path +
                  "' holds no drive: neither a KITTI odometry sequence (calib.txt, image_0/), a KITTI raw drive "
                  "(image_00/data/ below a date folder with calib_cam_to_cam.txt), a folder of the generic layout "
                  "(left/, right/, lidar/, rig.yaml), a ROS bag, nor a folder of them (sequences/NN, "
                  "DATE/DATE_drive_NNNN_sync, STREET/sequences/00, NAME/left/..., NAME.bag)");
  std::vector<Drive> drives;
  for (const fs::path& p : found)
    drives.push_back({"", p.string(), ""});
  return drives;
}

std::vector<Drive> readDriveList(const std::string& path) {
  requireFile(path, "drive list");
  std::ifstream in(path);
  const fs::path base = normal(path).parent_path();
  std::vector<Drive> drives;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#')
      continue;
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    std::vector<std::string> fields;
    if (line.find('\t') != std::string::npos) {
      std::stringstream ss(line);
      for (std::string f; std::getline(ss, f, '\t');) {
        const auto first = f.find_first_not_of(' '), last = f.find_last_not_of(' ');
        if (first != std::string::npos)
          fields.push_back(f.substr(first, last - first + 1));
      }
    } else {
      std::stringstream ss(line);
      for (std::string f; ss >> f;)
        fields.push_back(f);
    }
    const std::string where = "drive list '" + path + "' line " + std::to_string(number);
    if (fields.empty() || fields.size() > 2)
      throw IOError(where + ": expected 'DATASET [POSES]', got '" + line + "'");
    const fs::path dataset = fs::path(fields[0]).is_absolute() ? fs::path(fields[0]) : base / fields[0];
    const fs::path sequence = sequenceOf(normal(dataset.string()));
    if (sequence.empty())
      throw IOError(where + ": '" + fields[0] + "' is not a drive (" + kDriveLayouts + " with one sequence)");
    Drive drive{"", sequence.string(), ""};
    if (fields.size() == 2) {
      const fs::path poses = fs::path(fields[1]).is_absolute() ? fs::path(fields[1]) : base / fields[1];
      if (!isFile(poses))
        throw IOError(where + ": poses file '" + fields[1] + "' does not exist");
      drive.poses = normal(poses.string()).string();
    }
    drives.push_back(drive);
  }
  if (drives.empty())
    throw IOError("drive list '" + path + "' names no drive");
  return drives;
}

void nameDrives(std::vector<Drive>& drives) {
  std::map<std::string, std::string> seen_names, seen_datasets;
  for (Drive& d : drives) {
    const fs::path p(d.dataset);
    // A synthetic street (ROOT/sequences/00 with ROOT/gt) is named by its root.
    const fs::path root = p.parent_path().parent_path();
    d.name = isOdometrySequence(p) && p.parent_path().filename() == "sequences" && isDir(root / "gt")
                 ? root.filename().string()
             : isBag(p) ? p.stem().string() // drive_07.bag: drive_07
                        : p.filename().string();
    if (const auto it = seen_datasets.find(d.dataset); it != seen_datasets.end())
      throw InvalidInputError("dataset '" + d.dataset + "' is given twice");
    if (const auto it = seen_names.find(d.name); it != seen_names.end())
      throw InvalidInputError("drives '" + it->second + "' and '" + d.dataset + "' would both be named '" + d.name +
                              "' (OUT/drives/" + d.name + "): rename a folder or list them from one dataset root");
    seen_names[d.name] = d.dataset;
    seen_datasets[d.dataset] = d.name;
  }
}

std::unique_ptr<FrameSource> openDrive(const Drive& drive) {
  try {
    return openDataset(drive.dataset);
  } catch (const Error& e) {
    throw InvalidInputError("drive '" + drive.name + "': " + e.what() +
                            ". msf_batch reads a folder with its rig.yaml and a bag by kitti2bag's topics: "
                            "msf_convert DATASET DIR, with -rig FILE or the bag's topic options, writes one it reads");
  }
}

} // namespace msf
