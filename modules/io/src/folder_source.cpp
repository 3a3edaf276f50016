// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/io/beam_elevations.h>
#include <msf/io/folder_source.h>
#include <msf/io/image_io.h>
#include <msf/io/scan_file.h>
#include <msf/io/tum_poses.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>

namespace fs = std::filesystem;

namespace msf {

namespace {

const std::vector<std::string> kImageExtensions = {".png", ".jpg", ".jpeg"};
const std::vector<std::string> kScanExtensions = {".bin", ".pcd", ".ply"};

bool isNumber(const std::string& s) {
  return !s.empty() && s.size() <= 18 && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

/// The numbered files of `dir` with one of `extensions`, by stem; a stem given twice (000001.png
/// and 000001.jpg) is an error naming both.
std::map<std::string, std::string> numberedFiles(const fs::path& dir, const std::vector<std::string>& extensions) {
  std::map<std::string, std::string> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string stem = e.path().stem().string();
    const std::string ext = fileExtension(e.path().string());
    if (!e.is_regular_file() || !isNumber(stem) ||
        std::find(extensions.begin(), extensions.end(), ext) == extensions.end())
      continue; // not a frame: a hidden file, a README, a thumbnail
    const auto [it, fresh] = files.emplace(stem, e.path().string());
    if (!fresh)
      throw IOError("frame " + stem + " has two files in '" + dir.string() + "': '" + it->second + "' and '" +
                    e.path().string() + "'");
  }
  return files;
}

cv::Mat grey(const cv::Mat& image, int bits) {
  const cv::Mat bytes = toEightBit(image, bits);
  if (bytes.channels() == 1)
    return bytes;
  cv::Mat out;
  cv::cvtColor(bytes, out, bytes.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return out;
}

cv::Mat colour(const cv::Mat& image, int bits) {
  const cv::Mat bytes = toEightBit(image, bits);
  if (bytes.channels() == 3)
    return bytes;
  cv::Mat out;
  cv::cvtColor(bytes, out, bytes.channels() == 4 ? cv::COLOR_BGRA2BGR : cv::COLOR_GRAY2BGR);
  return out;
}

std::vector<std::string> contentLines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos && line[line.find_first_not_of(" \t\r")] != '#')
      lines.push_back(line);
  return lines;
}

} // namespace

bool FolderSource::looksLikeOne(const std::string& dir) {
  std::error_code ec;
  const fs::path p(dir);
  return fs::is_directory(p / "left", ec) && fs::is_directory(p / "right", ec) && fs::is_directory(p / "lidar", ec);
}

FolderSource::FolderSource(const std::string& dir, const std::string& rig) {
  requireDirectory(dir, "dataset folder");
  fs::path p = fs::absolute(dir).lexically_normal();
  if (p.filename().empty())
    p = p.parent_path();
  dir_ = p.string();
  if (!looksLikeOne(dir_))
    throw IOError("folder '" + dir_ + "' is not a dataset of the generic layout: it needs left/, right/ and lidar/");
  const std::string rig_file = rig.empty() ? (p / "rig.yaml").string() : rig;
  if (rig.empty() && !fs::exists(rig_file))
    throw IOError("dataset '" + dir_ + "' has no rig.yaml: write one (docs/usage.md, \"Your own rig\") or give -rig FILE");
  calibration_ = loadCalibration(rig_file);
  calibration_.requireVelodyne();
  findFrames();
  if (calibration_.image_size.area() <= 0) // a calibration without a size (KITTI's calib.txt): the images give it
    calibration_.image_size = readImage(frames_.front().left, cv::IMREAD_UNCHANGED).size();
  readTimes();
  readPoses();
  beamsFromFirstScan();
}

void FolderSource::beamsFromFirstScan() {
  // A KITTI .bin holds no rings: its scan is not read for them.
  if (!calibration_.lidar.beam_elevations_deg.empty() || fs::path(frames_.front().scan).extension() == ".bin")
    return;
  const ScanFile first = loadScanFile(frames_.front().scan);
  const std::vector<double> beams = beamElevationsFromRings(first.points, first.ring);
  if (beams.empty())
    return;
  calibration_.lidar.beam_elevations_deg = beams;
  calibration_.lidar.rings = static_cast<int>(beams.size());
  notes_.push_back(beamsFromRingsNote(beams));
}

void FolderSource::findFrames() {
  const fs::path p(dir_);
  const auto left = numberedFiles(p / "left", kImageExtensions);
  const auto right = numberedFiles(p / "right", kImageExtensions);
  const auto scans = numberedFiles(p / "lidar", kScanExtensions);
  const auto color = numberedFiles(p / "color", kImageExtensions);
  if (left.empty())
    throw IOError("dataset '" + dir_ + "' has no frames: no PNG or JPEG image in left/ named by a frame number of up "
                  "to 18 digits (000000.png, 000001.png, ...; timestamps.txt gives their times)");
  for (const auto& [name, path] : left) {
    FrameFiles f;
    f.name = name;
    f.number = std::stoull(name);
    f.left = path;
    const auto need = [&](const std::map<std::string, std::string>& files, const char* folder) {
      const auto it = files.find(name);
      if (it == files.end())
        throw IOError("dataset '" + dir_ + "': frame " + name + " has no file in " + folder + "/");
      return it->second;
    };
    f.right = need(right, "right");
    f.scan = need(scans, "lidar");
    if (!color.empty())
      f.color = need(color, "color");
    frames_.push_back(f);
  }
  std::sort(frames_.begin(), frames_.end(), [](const FrameFiles& a, const FrameFiles& b) { return a.number < b.number; });
  has_color_ = !color.empty() || readImage(frames_.front().left, cv::IMREAD_UNCHANGED).channels() >= 3;
  // A scan or right image without a left one is a mixed or damaged copy: its frame would be lost unsaid.
  for (const auto* files : {&right, &scans})
    for (const auto& [name, path] : *files)
      if (!left.count(name))
        throw IOError("dataset '" + dir_ + "': '" + path + "' has no left image (left/" + name + ".png)");
}

void FolderSource::readTimes() {
  const fs::path file = fs::path(dir_) / "timestamps.txt";
  if (!fs::exists(file)) {
    for (const FrameFiles& f : frames_)
      timestamps_.push_back(0.1 * static_cast<double>(f.number));
  } else {
    const std::vector<std::string> lines = contentLines(file);
    for (const FrameFiles& f : frames_) {
      if (f.number >= lines.size())
        throw IOError("'" + file.string() + "' has " + std::to_string(lines.size()) + " times and none for frame " +
                      f.name + " (line i is frame i)");
      std::size_t used = 0;
      double t = 0;
      try {
        t = std::stod(lines[f.number], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || !std::isfinite(t))
        throw IOError("'" + file.string() + "': the time of frame " + f.name + " '" + lines[f.number] +
                      "' is not a number of seconds");
      timestamps_.push_back(t);
    }
  }
  for (std::size_t i = 1; i < timestamps_.size(); ++i)
    if (!(timestamps_[i] > timestamps_[i - 1]))
      throw IOError("dataset '" + dir_ + "': the time of frame " + frames_[i].name + " does not follow frame " +
                    frames_[i - 1].name + "'s");
}

void FolderSource::readPoses() {
  const fs::path file = fs::path(dir_) / "poses.txt";
  if (!fs::exists(file))
    return;
  poses_file_ = file.string();
  if (isTumPoses(poses_file_)) {
    // Matched by time: within a quarter of the frames' smallest spacing.
    const StampedPoses tum = loadTumPoses(poses_file_);
    double spacing = 1.0;
    for (std::size_t i = 1; i < timestamps_.size(); ++i)
      spacing = std::min(spacing, timestamps_[i] - timestamps_[i - 1]);
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      const auto it = std::lower_bound(tum.timestamps.begin(), tum.timestamps.end(), timestamps_[i] - spacing / 4);
      if (it == tum.timestamps.end() || std::abs(*it - timestamps_[i]) > spacing / 4)
        throw IOError("poses '" + poses_file_ + "' has no pose within " + std::to_string(spacing / 4) +
                      " s of frame " + frames_[i].name + "'s time " + std::to_string(timestamps_[i]));
      poses_.push_back(tum.poses[static_cast<std::size_t>(it - tum.timestamps.begin())]);
    }
    return;
  }
  const PoseList all = loadOdometryPoses(poses_file_);
  for (const FrameFiles& f : frames_) {
    if (f.number >= all.size())
      throw IOError("poses '" + poses_file_ + "' has " + std::to_string(all.size()) + " poses and none for frame " +
                    f.name + " (line i is frame i)");
    poses_.push_back(all[f.number]);
  }
}

void FolderSource::checkIndex(std::size_t i) const {
  if (i >= size())
    throw InvalidInputError("frame " + std::to_string(i) + " is out of range: dataset '" + dir_ + "' has " +
                            std::to_string(size()) + " frames");
}

pcl::PointCloud<pcl::PointXYZI>::Ptr FolderSource::frameScan(pcl::PointCloud<pcl::PointXYZI>&& points,
                                                             std::size_t i) const {
  auto scan = pcl::make_shared<pcl::PointCloud<pcl::PointXYZI>>(std::move(points));
  scan->header.frame_id = kVelodyneFrameId;
  scan->header.stamp = static_cast<std::uint64_t>(std::llround(std::max(0.0, timestamp(i)) * 1e6));
  return scan;
}

pcl::PointCloud<pcl::PointXYZI>::Ptr FolderSource::loadScan(std::size_t i) const {
  checkIndex(i);
  return frameScan(std::move(loadScanFile(frames_[i].scan).points), i);
}

Frame FolderSource::load(std::size_t i, bool with_color) const {
  checkIndex(i);
  const FrameFiles& files = frames_[i];
  auto read = [](const std::string& path) {
    return std::async(std::launch::async, [path] { return readImage(path, cv::IMREAD_UNCHANGED); });
  };
  auto left = read(files.left), right = read(files.right);
  std::future<cv::Mat> color;
  if (with_color && !files.color.empty())
    color = read(files.color);
  Frame f;
  f.index = i;
  f.timestamp = timestamp(i);
  ScanFile scan = loadScanFile(files.scan);
  f.scan = frameScan(std::move(scan.points), i);
  f.point_ring = std::move(scan.ring);
  f.point_time_s = std::move(scan.time_s);
  const cv::Mat left_image = left.get(), right_image = right.get();
  const int pair_bits = pairBits(left_image, right_image);
  f.left = grey(left_image, pair_bits);
  f.right = grey(right_image, pair_bits);
  if (color.valid()) {
    const cv::Mat color_image = color.get();
    f.color = colour(color_image, significantBits(color_image));
  } else if (with_color && left_image.channels() >= 3) {
    f.color = colour(left_image, pair_bits);
  }
  const cv::Size size = calibration_.image_size;
  for (const auto& [image, path] : {std::pair<const cv::Mat*, const std::string*>{&f.left, &files.left},
                                    {&f.right, &files.right}, {&f.color, &files.color}})
    if (!image->empty() && image->size() != size)
      throw InvalidInputError("frame " + files.name + ": image '" + *path + "' is " + std::to_string(image->cols) +
                              "x" + std::to_string(image->rows) + ", not the rig's " + std::to_string(size.width) +
                              "x" + std::to_string(size.height));
  if (!poses_.empty()) {
    f.has_pose = true;
    f.T_world_cam0 = poses_[i];
  }
  return f;
}

} // namespace msf
