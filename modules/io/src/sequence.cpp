// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/message_text.h>
#include <msf/io/image_io.h>
#include <msf/io/folder_source.h>
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <future>

namespace fs = std::filesystem;

namespace msf {

namespace {

/// The stems of the files of `dir` named by a frame number with extension `ext`, sorted;
/// other files (.DS_Store, a README, a copy) are not frames.
std::vector<std::string> stemsIn(const fs::path& dir, const std::string& ext) {
  std::vector<std::string> stems;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return stems;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file(ec) && e.path().extension() == ext && frameNumber(e.path().stem().string()) >= 0)
      stems.push_back(e.path().stem().string());
  const auto before = [](const std::string& a, const std::string& b) { return frameNumber(a) < frameNumber(b); };
  const auto same = [](const std::string& a, const std::string& b) { return frameNumber(a) == frameNumber(b); };
  std::sort(stems.begin(), stems.end(), before);
  const auto twice = std::adjacent_find(stems.begin(), stems.end(), same);
  if (twice != stems.end())
    throw IOError("folder '" + dir.string() + "' holds frame " + std::to_string(frameNumber(*twice)) + " twice: '" +
                  *twice + ext + "' and '" + *(twice + 1) + ext + "'");
  return stems;
}

/// "2011-09-26 13:08:24.969505176" -> seconds of the day (the date does not change in a drive);
/// NaN when the line is not such a time.
double parseRawTimestamp(const std::string& line) {
  int h = 0, m = 0;
  double s = 0;
  if (line.size() < 19 || std::sscanf(line.c_str() + 11, "%d:%d:%lf", &h, &m, &s) != 3)
    return std::nan("");
  return h * 3600.0 + m * 60.0 + s;
}

/// A line of an odometry times.txt (seconds) or of a raw drive's timestamps.txt (a date and
/// time); NaN when it is neither.
double parseTime(const std::string& line, bool raw_format) {
  if (raw_format)
    return parseRawTimestamp(line);
  char* end = nullptr;
  const double t = std::strtod(line.c_str(), &end);
  const char* rest = end;
  const bool rest_blank = std::all_of(rest, line.c_str() + line.size(), [](unsigned char c) { return std::isspace(c); });
  return end != line.c_str() && rest_blank ? t : std::nan("");
}

/// The times of a timestamps file from its first line's, line n for frame n; empty when the
/// file is absent. Throws IOError naming the file and line of a value that is not a time, or
/// that does not follow the line before (frames matched by time, and the TUM poses written,
/// need increasing times).
std::vector<double> readTimestamps(const fs::path& file, bool raw_format) {
  std::vector<double> t;
  std::ifstream in(file);
  std::string line;
  for (std::size_t line_no = 1; std::getline(in, line); ++line_no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos && in.peek() == std::char_traits<char>::eof())
      break; // a blank last line
    const double time = parseTime(line, raw_format);
    const std::string where = "timestamps '" + file.string() + "' line " + std::to_string(line_no) + " '" + line + "'";
    if (!std::isfinite(time))
      throw IOError(where + " is not a time");
    if (!t.empty() && !(time > t.back()))
      throw IOError(where + " does not follow line " + std::to_string(line_no - 1) + "'s: the times must increase");
    t.push_back(time);
  }
  const double t0 = t.empty() ? 0.0 : t.front();
  for (double& x : t)
    x -= t0;
  return t;
}

/// The entries of `by_number` (frame n's at n) of the frames `names`, in their order. Throws
/// IOError naming the first frame beyond it, and `what` ("poses 'poses/04.txt'").
template <typename List>
List ofFrames(const List& by_number, const std::vector<std::string>& names, const std::string& what) {
  List out;
  out.reserve(names.size());
  for (const std::string& name : names) {
    const auto n = static_cast<std::size_t>(frameNumber(name));
    if (n >= by_number.size())
      throw IOError("frame " + name + " has no entry in " + what + ", which has " + std::to_string(by_number.size()) +
                    " (frames 0.." + std::to_string(static_cast<long long>(by_number.size()) - 1) + ")");
    out.push_back(by_number[n]);
  }
  return out;
}

/// OXTS poses of the frames `names` of a raw drive, from each frame's record oxts/data/<name>.txt.
PoseList oxtsPosesOfFrames(const fs::path& oxts_dir, const std::vector<std::string>& names,
                           const Calibration& calibration) {
  std::vector<OxtsRecord> records;
  for (const std::string& name : names) {
    const fs::path record = oxts_dir / (name + ".txt");
    if (!fs::is_regular_file(record))
      throw IOError("frame " + name + " has no OXTS record: '" + record.string() + "' is missing");
    records.push_back(loadOxtsRecord(record.string()));
  }
  return oxtsToCameraPoses(records, calibration);
}

bool isOdometrySequence(const fs::path& p) {
  return fs::is_regular_file(p / "calib.txt") && fs::is_directory(p / "image_0");
}

} // namespace

Sequence::Sequence(const std::string& dir, const std::string& calibration) {
  requireDirectory(dir, "sequence");
  fs::path p = fs::absolute(dir).lexically_normal();
  if (p.filename().empty())
    p = p.parent_path();
  std::error_code ec;

  if (!isOdometrySequence(p) && fs::is_directory(p / "sequences", ec)) {
    // A dataset root: accept it when it holds exactly one sequence.
    std::vector<fs::path> found;
    for (const auto& e : fs::directory_iterator(p / "sequences"))
      if (isOdometrySequence(e.path()))
        found.push_back(e.path());
    if (found.size() != 1)
      throw IOError("dataset '" + dir + "' holds " + std::to_string(found.size()) +
                    " sequences under sequences/; name one of them");
    p = found.front();
  }

  std::vector<double> times;
  if (isOdometrySequence(p)) {
    layout_ = Layout::Odometry;
    dir_ = p.string();
    // A rig file beside calib.txt (msf_synth writes both) also says what the LiDAR's beams are.
    calibration_ = loadCalibration((fs::is_regular_file(p / "rig.yaml", ec) ? p / "rig.yaml" : p / "calib.txt").string());
    frame_names_ = stemsIn(p / "image_0", ".png");
    times = readTimestamps(p / "times.txt", false);
    const fs::path root = p.parent_path().parent_path();
    const fs::path poses = root / "poses" / (p.filename().string() + ".txt");
    if (fs::is_regular_file(poses, ec))
      poses_ = ofFrames(loadOdometryPoses(poses.string()), frame_names_, "poses '" + poses.string() + "'");
    if (fs::is_directory(root / "gt", ec))
      gt_dir_ = (root / "gt").string();
    if (fs::is_regular_file(root / "gt" / "poses.txt", ec))
      true_poses_ = ofFrames(loadOdometryPoses((root / "gt" / "poses.txt").string()), frame_names_,
                             "the true poses '" + (root / "gt" / "poses.txt").string() + "'");
    // msf_synth's LiDAR takes a scan at one instant; a sequence it wrote before it wrote rig
    // files says so by its truth alone.
    if (!gt_dir_.empty() && !fs::is_regular_file(p / "rig.yaml", ec))
      calibration_.lidar.sweeping = false;
  } else if (fs::is_directory(p / "image_00" / "data", ec) &&
             fs::is_regular_file(p.parent_path() / "calib_cam_to_cam.txt", ec)) {
    layout_ = Layout::Raw;
    dir_ = p.string();
    calibration_ = loadCalibration(p.parent_path().string());
    frame_names_ = stemsIn(p / "image_00" / "data", ".png");
    times = readTimestamps(p / "image_00" / "timestamps.txt", true);
    if (fs::is_directory(p / "oxts" / "data", ec) && calibration_.has_imu)
      poses_ = oxtsPosesOfFrames(p / "oxts" / "data", frame_names_, calibration_);
  } else if (FolderSource::looksLikeOne(dir)) {
    throw IOError("'" + dir + "' is a folder of your own rig's layout (left/, right/, lidar/): msf_reconstruct, "
                  "msf_odometry, msf_eval_odometry and msfusion.open_dataset read it (openDataset); this reader "
                  "takes KITTI's layouts and msf_synth's");
  } else {
    throw IOError("'" + dir +
                  "' is neither a KITTI odometry sequence (calib.txt, image_0/), a KITTI raw drive "
                  "(image_00/data/ with calib_cam_to_cam.txt in the folder above) nor a folder of your own rig's "
                  "layout (left/, right/, lidar/, rig.yaml)");
  }
  if (!calibration.empty())
    calibration_ = loadCalibration(calibration);
  if (frame_names_.empty())
    throw IOError("sequence '" + dir_ + "' has no frames (no images named by a frame number in camera 0's folder)");
  if (!times.empty())
    timestamps_ = ofFrames(times, frame_names_, "the timestamps of '" + dir_ + "'");
  // More right images or scans than frames is a damaged or mixed copy whose extra frames
  // would be dropped without a word (a frame whose file is missing is named when it loads).
  for (const auto& [folder, ext] : {std::pair<fs::path, const char*>{fs::path(imagePath(1, 0)).parent_path(), ".png"},
                                    {fs::path(scanPath(0)).parent_path(), ".bin"}}) {
    const std::size_t n = fs::is_directory(folder, ec) ? stemsIn(folder, ext).size() : 0;
    if (n > frame_names_.size())
      throw IOError("sequence '" + dir_ + "' has " + std::to_string(frame_names_.size()) + " images in camera 0's " +
                    "folder but " + std::to_string(n) + " " + ext + " files in '" + folder.string() + "'");
  }
  if (calibration_.image_size.width <= 0)
    calibration_.image_size = readImage(imagePath(0, 0), cv::IMREAD_GRAYSCALE).size();
}

std::string Sequence::posesName() const {
  if (!true_poses_.empty())
    return "the synthetic INS";
  if (!gt_dir_.empty())
    return "the synthetic ground truth";
  return layout_ == Layout::Raw ? "OXTS (GPS/IMU)" : "the odometry ground truth";
}

bool Sequence::posesAreMeasured() const {
  return !poses_.empty() && (layout_ == Layout::Raw || !true_poses_.empty());
}

std::string Sequence::referencePosesName() const {
  return true_poses_.empty() ? posesName() : "the synthetic ground truth (gt/poses.txt)";
}

std::string Sequence::scanPath(std::size_t i) const {
  const fs::path p(dir_);
  if (layout_ == Layout::Odometry)
    return (p / "velodyne" / (frameName(i) + ".bin")).string();
  return (p / "velodyne_points" / "data" / (frameName(i) + ".bin")).string();
}

std::string Sequence::imagePath(int camera, std::size_t i) const {
  Calibration::checkCamera(camera);
  const fs::path p(dir_);
  if (layout_ == Layout::Odometry)
    return (p / ("image_" + std::to_string(camera)) / (frameName(i) + ".png")).string();
  return (p / ("image_0" + std::to_string(camera)) / "data" / (frameName(i) + ".png")).string();
}

void Sequence::checkIndex(std::size_t i) const {
  if (i >= size())
    throw InvalidInputError("frame " + std::to_string(i) + " is out of range: sequence '" + dir_ + "' has " +
                            std::to_string(size()) + " frames");
}

pcl::PointCloud<pcl::PointXYZI>::Ptr Sequence::loadScan(std::size_t i) const {
  checkIndex(i);
  pcl::PointCloud<pcl::PointXYZI>::Ptr scan(new pcl::PointCloud<pcl::PointXYZI>);
  loadVelodyneBin(scanPath(i), *scan);
  if (scan->empty())
    throw IOError("frame " + frameName(i) + ": scan '" + scanPath(i) + "' has no finite point");
  scan->header.frame_id = kVelodyneFrameId; // the stages carry its stamp into camera 0
  scan->header.stamp = static_cast<std::uint64_t>(std::llround(std::max(0.0, timestamp(i)) * 1e6));
  scan->header.seq = static_cast<std::uint32_t>(i);
  return scan;
}

Frame Sequence::load(std::size_t i, bool with_color) const {
  checkIndex(i);
  Frame f;
  f.index = i;
  f.timestamp = timestamp(i);
  // The three PNG decodes (zlib: ~18 ms per KITTI frame) run beside the scan's loading: the
  // first frame of a pipeline waits for them with the other stages idle. A failure's
  // exception reaches the caller through its future.
  auto read = [](std::string path, int flags) {
    return std::async(std::launch::async, [path = std::move(path), flags] { return readImage(path, flags); });
  };
  auto left = read(imagePath(0, i), cv::IMREAD_GRAYSCALE);
  auto right = read(imagePath(1, i), cv::IMREAD_GRAYSCALE);
  std::future<cv::Mat> color;
  if (with_color && fs::exists(imagePath(2, i)))
    color = read(imagePath(2, i), cv::IMREAD_COLOR);
  else if (with_color && fs::is_directory(fs::path(imagePath(2, i)).parent_path()))
    throw IOError("frame " + frameName(i) + ": colour image '" + imagePath(2, i) +
                  "' is missing (camera 2's folder holds other frames)");
  f.scan = loadScan(i);
  f.left = left.get();
  f.right = right.get();
  if (color.valid())
    f.color = color.get();
  const cv::Size size = calibration_.image_size;
  const std::pair<const cv::Mat*, int> images[] = {{&f.left, 0}, {&f.right, 1}, {&f.color, 2}};
  for (const auto& [image, camera] : images)
    if (!image->empty() && image->size() != size)
      throw InvalidInputError("frame " + frameName(i) + ": image '" + imagePath(camera, i) + "' is " +
                              std::to_string(image->cols) + "x" + std::to_string(image->rows) +
                              ", not the calibration's " + std::to_string(size.width) + "x" +
                              std::to_string(size.height));
  if (hasPoses()) {
    f.has_pose = true;
    f.T_world_cam0 = poses_[i];
  }
  return f;
}

double Sequence::timestamp(std::size_t i) const {
  // Without timestamps, KITTI's 10 Hz by the frame's number.
  return i < timestamps_.size() ? timestamps_[i] : 0.1 * static_cast<double>(frameNumber(frameName(i)));
}

bool Sequence::hasColor() const {
  std::error_code ec;
  return fs::is_directory(fs::path(imagePath(2, 0)).parent_path(), ec);
}

} // namespace msf
