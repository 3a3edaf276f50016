// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/yaml_check.h>
#include <opencv2/core.hpp>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/common/message_text.h>
#include <msf/io/calibration.h>
#include <msf/io/rig_file.h>
#include <msf/io/image_io.h>

#include <opencv2/core/persistence.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;

namespace msf {

void Calibration::throwNoSuchCamera(int camera) {
  throw InvalidInputError("camera index " + std::to_string(camera) + " is not 0..3");
}

Eigen::Vector3d Calibration::cameraCenter(int camera) const {
  // P = K [R | t] with R = I for rectified cameras: centre = -K^-1 * P.col(3).
  return -(K(camera).inverse() * projection(camera).col(3));
}

double Calibration::baseline(int camera_a, int camera_b) const {
  return (cameraCenter(camera_a) - cameraCenter(camera_b)).norm();
}

cv::Size Calibration::requireImageSize() const {
  if (image_size.width <= 0 || image_size.height <= 0)
    throw CalibrationError("calibration '" + source +
                           "' has no image size (no S_rect_00 key and no image beside it; the tools take -image_size WxH)");
  return image_size;
}

void Calibration::requireVelodyne() const {
  if (!has_velodyne)
    throw CalibrationError("calibration '" + source +
                           "' holds the cameras only (no LiDAR extrinsic: a rig file's lidar.T_cam_lidar, KITTI's 'Tr' or "
                           "'Tr_velo_to_cam', or 'T_cam0_velo'): projecting a "
                           "scan needs the LiDAR's extrinsics");
}

namespace {

/// "KEY: v1 v2 ..." lines of a KITTI calibration text file.
class KeyValueFile {
public:
  explicit KeyValueFile(const std::string& path) : path_(path) {
    requireFile(path, "calibration");
    std::ifstream in(path);
    if (!in)
      throw IOError("calibration '" + path + "' cannot be read");
    std::string line;
    std::map<std::string, int> line_of;
    for (int line_no = 1; std::getline(in, line); ++line_no) {
      const auto colon = line.find(':');
      if (colon == std::string::npos)
        continue;
      std::string key = line.substr(0, colon);
      key.erase(0, key.find_first_not_of(" \t"));
      key.erase(key.find_last_not_of(" \t\r") + 1);
      // A key given twice (a pasted line, two files joined): which one is meant is unknown.
      const auto [first, fresh] = line_of.emplace(key, line_no);
      if (!fresh)
        throw CalibrationError("calibration '" + path + "': key '" + key + "' is given twice, on lines " +
                               std::to_string(first->second) + " and " + std::to_string(line_no));
      std::istringstream values(line.substr(colon + 1));
      std::vector<double> numbers;
      std::string token, bad;
      while (values >> token) {
        try {
          std::size_t used = 0;
          numbers.push_back(std::stod(token, &used));
          if (used != token.size() && bad.empty())
            bad = token;
        } catch (const std::exception&) {
          if (bad.empty())
            bad = token;
        }
      }
      // A line that is not numbers (a date, a comment) is kept as such: asking for its key
      // names the value at fault, not a missing key.
      if (bad.empty())
        entries_[key] = numbers;
      else
        not_numeric_[key] = bad;
    }
  }

  bool has(const std::string& key) const { return entries_.count(key) > 0 || not_numeric_.count(key) > 0; }

  std::vector<double> get(const std::string& key, std::size_t count) const {
    const auto it = entries_.find(key);
    if (it == entries_.end()) {
      const auto bad = not_numeric_.find(key);
      if (bad != not_numeric_.end())
        throw CalibrationError("calibration '" + path_ + "': key '" + key + "' has a value that is not a number: '" +
                               bad->second + "'");
      throw CalibrationError("calibration '" + path_ + "' has no key '" + key + "'");
    }
    if (it->second.size() != count)
      throw CalibrationError("calibration '" + path_ + "': key '" + key + "' has " +
                             std::to_string(it->second.size()) + " values, expected " +
                             std::to_string(count));
    return it->second;
  }

  Calibration::Projection projection(const std::string& key) const {
    const auto v = get(key, 12);
    Calibration::Projection P;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        P(r, c) = v[r * 4 + c];
    return P;
  }

  Eigen::Isometry3d transform3x4(const std::string& key) const {
    const auto v = get(key, 12);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        T.matrix()(r, c) = v[r * 4 + c];
    return T;
  }

  Eigen::Matrix3d rotation(const std::string& key) const {
    const auto v = get(key, 9);
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        R(r, c) = v[r * 3 + c];
    return R;
  }

  /// The devkit's R + T files (calib_velo_to_cam.txt, calib_imu_to_velo.txt).
  Eigen::Isometry3d rigid() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = rotation("R");
    const auto t = get("T", 3);
    T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
    return T;
  }

  const std::string& path() const { return path_; }

private:
  std::string path_;
  std::map<std::string, std::vector<double>> entries_;
  std::map<std::string, std::string> not_numeric_; ///< key -> its first value that is not a number
};

cv::Size imageSizeOf(const fs::path& image) {
  std::error_code ec;
  if (!fs::is_regular_file(image, ec))
    return {0, 0};
  return readImage(image.string()).size();
}

/// The first .png of `dir` by name: a frame image, not a stray file (.DS_Store, a README).
fs::path firstImage(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return {};
  fs::path first;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file(ec) && e.path().extension() == ".png" && e.path().stem().string()[0] != '.' &&
        (first.empty() || e.path() < first))
      first = e.path();
  return first;
}

Calibration fromOdometry(const KeyValueFile& f) {
  Calibration c;
  c.source = f.path();
  for (int i = 0; i < 4; ++i)
    c.P[i] = f.projection("P" + std::to_string(i));
  c.has_velodyne = f.has("Tr");
  if (c.has_velodyne)
    c.T_cam0_velo = f.transform3x4("Tr");
  c.image_size = imageSizeOf(firstImage(fs::path(f.path()).parent_path() / "image_0"));
  return c;
}

Calibration fromObject(const KeyValueFile& f) {
  Calibration c;
  c.source = f.path();
  for (int i = 0; i < 4; ++i)
    c.P[i] = f.projection("P" + std::to_string(i));
  Eigen::Isometry3d R0 = Eigen::Isometry3d::Identity();
  R0.linear() = f.rotation("R0_rect");
  c.T_cam0_velo = R0 * f.transform3x4("Tr_velo_to_cam");
  // calib/NNNNNN.txt -> image_2/NNNNNN.png
  const fs::path p(f.path());
  c.image_size = imageSizeOf(p.parent_path().parent_path() / "image_2" / (p.stem().string() + ".png"));
  return c;
}

Calibration fromRawDateFolder(const fs::path& date_dir) {
  const KeyValueFile cam((date_dir / "calib_cam_to_cam.txt").string());
  const KeyValueFile velo((date_dir / "calib_velo_to_cam.txt").string());
  Calibration c;
  c.source = date_dir.string();
  for (int i = 0; i < 4; ++i)
    c.P[i] = cam.projection("P_rect_0" + std::to_string(i));
  const auto size = cam.get("S_rect_00", 2);
  if (!(size[0] >= 1 && size[0] <= limits::kMaxImageSide && size[1] >= 1 && size[1] <= limits::kMaxImageSide))
    limits::checkImageSize(-1, -1, "calibration '" + cam.path() + "': key 'S_rect_00'");
  c.image_size = cv::Size(static_cast<int>(size[0]), static_cast<int>(size[1]));
  Eigen::Isometry3d R_rect = Eigen::Isometry3d::Identity();
  R_rect.linear() = cam.rotation("R_rect_00");
  c.T_cam0_velo = R_rect * velo.rigid();
  const fs::path imu = date_dir / "calib_imu_to_velo.txt";
  if (fs::exists(imu)) {
    c.T_velo_imu = KeyValueFile(imu.string()).rigid();
    c.has_imu = true;
  }
  return c;
}

/// An opencv-matrix of `rows` x `cols`, as doubles. Its rows, cols and number of values are
/// checked before OpenCV reads it: OpenCV allocates rows x cols first ("cols: ....4" asked
/// for 48 GB, found by fuzz/fuzz_calibration).
cv::Mat readMatrixYaml(const cv::FileStorage& in, const std::string& key, int rows, int cols, const std::string& path) {
  const cv::FileNode node = in[key];
  if (node.empty())
    throw CalibrationError("calibration '" + path + "' has no key '" + key + "'");
  const auto count = [](const cv::FileNode& n) { return n.isInt() ? static_cast<int>(n) : -1; };
  const int r = node.isMap() ? count(node["rows"]) : -1, c = node.isMap() ? count(node["cols"]) : -1;
  if (r != rows || c != cols)
    throw CalibrationError("calibration '" + path + "': key '" + key + "' is " +
                           (r < 0 || c < 0 ? std::string("not a matrix with integer rows and cols")
                                           : std::to_string(r) + "x" + std::to_string(c)) +
                           ", expected " + std::to_string(rows) + "x" + std::to_string(cols));
  // OpenCV converts the values to the matrix's type: 'u' clips them to 0..255, the integer
  // types drop their decimals.
  const cv::FileNode type = node["dt"];
  const std::string dt = type.isString() ? type.string() : std::string();
  if (dt != "d" && dt != "f")
    throw CalibrationError("calibration '" + path + "': key '" + key + "' has dt '" + dt +
                           "', not d (float64) or f (float32): OpenCV would clip or round its values to that type");
  const cv::FileNode data = node["data"];
  if (!data.isSeq() || data.size() != static_cast<std::size_t>(rows) * cols)
    throw CalibrationError("calibration '" + path + "': key '" + key + "' needs " + std::to_string(rows * cols) +
                           " values in 'data'");
  cv::Mat m;
  node >> m;
  m.convertTo(m, CV_64F);
  return m;
}

Calibration fromYamlNodes(const cv::FileStorage& in, const std::string& path);

Calibration fromYaml(const std::string& path) {
  requireYamlTopLevelAtColumnZero(path, "calibration");
  cv::FileStorage in;
  try {
    in.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw IOError("calibration '" + path + "' is not valid YAML: " + e.err);
  } catch (const std::exception& e) {
    // OpenCV's parser also throws std::length_error on some malformed files (fuzz/fuzz_calibration).
    throw IOError("calibration '" + path + "' is not valid YAML: " + e.what());
  }
  if (!in.isOpened())
    throw IOError("calibration '" + path + "' cannot be opened");
  try {
    return fromYamlNodes(in, path);
  } catch (const Error&) {
    throw;
  } catch (const cv::Exception& e) {
    // OpenCV asserts on a matrix whose data does not match rows x cols (fuzz/fuzz_calibration).
    throw CalibrationError("calibration '" + path + "' is not a valid camera file: " + e.err);
  } catch (const std::exception& e) {
    throw CalibrationError("calibration '" + path + "' is not a valid camera file: " + e.what());
  }
}

/// The LiDAR's description (Calibration::Lidar) as saveCalibrationYaml writes it: keys
/// lidar_sweeping (0 or 1), lidar_rings and lidar_beam_elevations_deg (1xN), each optional.
void readLidarYaml(const cv::FileStorage& in, const std::string& path, Calibration::Lidar& lidar) {
  const auto integer = [&](const char* key, int lowest, int highest) {
    const cv::FileNode node = in[key];
    if (!node.isInt() || static_cast<int>(node) < lowest || static_cast<int>(node) > highest)
      throw CalibrationError("calibration '" + path + "': key '" + key + "' must be an integer " +
                             std::to_string(lowest) + ".." + std::to_string(highest));
    return static_cast<int>(node);
  };
  if (!in["lidar_sweeping"].empty())
    lidar.sweeping = integer("lidar_sweeping", 0, 1) == 1;
  if (!in["lidar_rings"].empty())
    lidar.rings = integer("lidar_rings", 1, 1024);
  const cv::FileNode beams = in["lidar_beam_elevations_deg"];
  if (beams.empty())
    return;
  const int count = beams.isMap() && beams["cols"].isInt() ? static_cast<int>(beams["cols"]) : 0;
  const cv::Mat e = readMatrixYaml(in, "lidar_beam_elevations_deg", 1, std::max(count, 1), path);
  lidar.beam_elevations_deg.assign(e.begin<double>(), e.end<double>());
}

Calibration fromYamlNodes(const cv::FileStorage& in, const std::string& path) {
  Calibration c;
  c.source = path;
  for (int i = 0; i < 4; ++i) {
    const cv::Mat P = readMatrixYaml(in, "P" + std::to_string(i), 3, 4, path);
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 4; ++col)
        c.P[i](r, col) = P.at<double>(r, col);
  }
  for (const char* key : {"image_width", "image_height"})
    if (in[key].empty() || !in[key].isInt())
      throw CalibrationError("calibration '" + path + "' has no integer key '" + key + "'");
  c.image_size = cv::Size(static_cast<int>(in["image_width"]), static_cast<int>(in["image_height"]));
  limits::checkImageSize(c.image_size.width, c.image_size.height,
                         "calibration '" + path + "': keys 'image_width' and 'image_height'");
  c.has_velodyne = !in["T_cam0_velo"].empty(); // camera-only: no LiDAR extrinsics
  if (!c.has_velodyne)
    return c;
  const cv::Mat T = readMatrixYaml(in, "T_cam0_velo", 4, 4, path);
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col)
      c.T_cam0_velo.matrix()(r, col) = T.at<double>(r, col);
  readLidarYaml(in, path, c.lidar);
  return c;
}

} // namespace

namespace {
Calibration readCalibration(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  if (!fs::exists(p, ec))
    throw IOError("calibration '" + path + "' does not exist", path, ENOENT);
  if (fs::is_directory(p, ec)) {
    if (fs::exists(p / "calib_cam_to_cam.txt"))
      return fromRawDateFolder(p);
    if (fs::exists(p.parent_path() / "calib_cam_to_cam.txt")) // a drive folder
      return fromRawDateFolder(p.parent_path());
    // A rig file beside calib.txt (msf_synth writes both) also says what the LiDAR's beams are,
    // and a folder of the generic layout has it alone: read first, as the dataset readers read it.
    if (fs::is_regular_file(p / "rig.yaml", ec))
      return readCalibration((p / "rig.yaml").string());
    if (fs::exists(p / "calib.txt"))
      return fromOdometry(KeyValueFile((p / "calib.txt").string()));
    throw IOError("calibration folder '" + path +
                  "' has neither calib_cam_to_cam.txt (KITTI raw), rig.yaml (a rig file) nor calib.txt (KITTI "
                  "odometry)");
  }
  const std::string ext = fileExtension(path);
  if ((ext == ".yaml" || ext == ".yml") && isRigFile(path))
    return loadRigFile(path);
  if (ext == ".yaml" || ext == ".yml" || ext == ".xml")
    return fromYaml(path);
  if (p.filename() == "calib_cam_to_cam.txt")
    return fromRawDateFolder(p.has_parent_path() ? p.parent_path() : fs::path("."));
  const KeyValueFile f(path);
  if (f.has("Tr_velo_to_cam") || f.has("R0_rect"))
    return fromObject(f);
  if (f.has("P_rect_00"))
    return fromRawDateFolder(p.has_parent_path() ? p.parent_path() : fs::path("."));
  if (f.has("P0"))
    return fromOdometry(f);
  throw CalibrationError("calibration '" + path +
                         "' is not a KITTI odometry, raw or object calibration (no key P0, P_rect_00 or R0_rect)");
}
} // namespace

void Calibration::validate() const {
  const std::string where = "calibration '" + source + "'";
  for (int i = 0; i < 4; ++i) {
    const std::string key = "P" + std::to_string(i);
    if (!P[i].allFinite())
      throw CalibrationError(where + ": " + key + " has a value that is not finite (NaN or inf)");
    if (!(fx(i) > 0.0 && fy(i) > 0.0))
      throw CalibrationError(where + ": " + key + " has fx " + std::to_string(fx(i)) + " and fy " +
                             std::to_string(fy(i)) + ": focal lengths must be > 0");
    if (P[i].block<1, 3>(2, 0) != Eigen::RowVector3d(0, 0, 1))
      throw CalibrationError(where + ": " + key + "'s third row must start 0 0 1 (a rectified camera)");
    if (std::abs(P[i](0, 1)) > 1e-6 * fx(i) || std::abs(P[i](1, 0)) > 1e-6 * fx(i))
      throw CalibrationError(where + ": " + key + " has a skew or rotation term (P(0,1), P(1,0) must be 0)");
    if (!(cameraCenter(i).cwiseAbs().maxCoeff() <= limits::kMaxTranslationM))
      throw CalibrationError(where + ": " + key + "'s camera centre is beyond " +
                             std::to_string(limits::kMaxTranslationM) + " m");
  }
  if (image_size.width != 0 || image_size.height != 0)
    limits::checkImageSize(image_size.width, image_size.height, where);
  const std::vector<double>& beams = lidar.beam_elevations_deg;
  if (!beams.empty() && lidar.rings != 0 && lidar.rings != static_cast<int>(beams.size()))
    throw CalibrationError(where + ": lidar.rings is " + std::to_string(lidar.rings) + " but " +
                           "lidar.beam_elevations_deg holds " + std::to_string(beams.size()) +
                           ": one elevation per ring");
  for (std::size_t i = 0; i < beams.size(); ++i)
    if (!(std::abs(beams[i]) < 90.0) || (i > 0 && !(beams[i] > beams[i - 1])))
      throw CalibrationError(where + ": lidar.beam_elevations_deg must rise from the lowest beam to the highest, "
                                     "within -90 .. 90 degrees");
  try {
    limits::checkRigid(T_cam0_velo, where + ": the LiDAR-to-camera transform");
    if (has_imu)
      limits::checkRigid(T_velo_imu, where + ": the IMU-to-LiDAR transform");
  } catch (const InvalidInputError& e) {
    throw CalibrationError(e.what());
  }
}

double Calibration::focalBaseline() const {
  const std::string where = "calibration '" + source + "'";
  const double fb = fx(0) * baselineGrey();
  if (!(fb > 0.0) || !std::isfinite(fb))
    throw CalibrationError(where + ": the grey pair's focal length x baseline is " + std::to_string(fb) +
                           " (P0 and P1 must have fx > 0 and different centres) ");
  checkRectifiedPair(0, 1);
  const double step = cameraCenter(1).x() - cameraCenter(0).x();
  if (step < 0.0)
    throw CalibrationError(where + ": camera 1 is " + number(-step) + " m left of camera 0 (P1's fourth value " +
                           number(P[1](0, 3)) + " is positive; a rectified right camera has -fx x baseline there): "
                           "the grey images or the sign are swapped");
  const double baseline = baselineGrey();
  if (baseline < limits::kMinBaselineM || baseline > limits::kMaxBaselineM)
    throw CalibrationError(where + ": the grey pair's baseline is " + number(baseline) + " m, outside " +
                           number(limits::kMinBaselineM) + " .. " + number(limits::kMaxBaselineM) +
                           " m (below a millimetre a pair sees no depth; no rig is 10 m wide): a unit or a digit "
                           "is wrong");
  return fb;
}

void Calibration::checkRectifiedPair(int a, int b) const {
  const char* names[] = {"fx", "fy", "cx", "cy"};
  const double values[2][4] = {{fx(a), fy(a), cx(a), cy(a)}, {fx(b), fy(b), cx(b), cy(b)}};
  for (int k = 0; k < 4; ++k)
    if (!(std::abs(values[0][k] - values[1][k]) <= limits::kRectifiedIntrinsicsTolerancePx))
      throw CalibrationError("calibration '" + source + "': P" + std::to_string(b) + "'s " + names[k] + " " +
                             number(values[1][k]) + " is not P" + std::to_string(a) + "'s " + number(values[0][k]) +
                             ": the cameras of a rectified pair share their intrinsics");
  // P(1,3) = fy ty and P(2,3) = tz: a row shift of the tolerance at a metre at most.
  if (!(std::abs(P[b](1, 3) - P[a](1, 3)) <= limits::kRectifiedIntrinsicsTolerancePx) ||
      !(std::abs(P[b](2, 3) - P[a](2, 3)) <= limits::kRectifiedIntrinsicsTolerancePx / fy(a)))
    throw CalibrationError("calibration '" + source + "': P" + std::to_string(b) + " is shifted up, down or along "
                           "the axis from P" + std::to_string(a) + " (its fourth column's second or third value "
                           "differs): the cameras of a rectified pair differ along x only");
}

Calibration loadCalibration(const std::string& path) {
  Calibration c = readCalibration(path);
  c.validate();
  return c;
}

Calibration loadCalibration(const std::string& path, cv::Size image_size) {
  Calibration c = loadCalibration(path);
  if (image_size.width <= 0 || image_size.height <= 0)
    return c;
  if (c.image_size.width > 0 && c.image_size != image_size)
    throw CalibrationError("image size " + std::to_string(image_size.width) + "x" + std::to_string(image_size.height) +
                           " given, but calibration '" + path + "' has " + std::to_string(c.image_size.width) + "x" +
                           std::to_string(c.image_size.height));
  limits::checkImageSize(image_size.width, image_size.height, "the image size given");
  c.image_size = image_size;
  return c;
}

std::string cameraFrameId(int camera) { return "camera_" + std::to_string(camera); }

cv::Size parseImageSize(const std::string& text) {
  if (text.empty())
    return {0, 0};
  // Each side digits only, read without overflow: sscanf's %d read 99999999999 as 1215752191
  // (undefined behaviour), and the message named a size no one gave.
  const auto side = [](const std::string& digits) -> long long {
    if (digits.empty() || digits.size() > 18 || digits.find_first_not_of("0123456789") != std::string::npos)
      return 0;
    return std::stoll(digits);
  };
  const std::size_t x = text.find('x');
  const long long width = x == std::string::npos ? 0 : side(text.substr(0, x));
  const long long height = x == std::string::npos ? 0 : side(text.substr(x + 1));
  if (width <= 0 || height <= 0)
    throw InvalidInputError("image size '" + text + "' is not WIDTHxHEIGHT with both > 0 (e.g. 1242x375)");
  limits::checkImageSize(width, height, "the image size given");
  return {static_cast<int>(width), static_cast<int>(height)};
}

void saveCalibrationYaml(const Calibration& calibration, const std::string& path) {
  // Formatted in memory, then written checked (FileStorage does not check its writes).
  cv::FileStorage out(path, cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  for (int i = 0; i < 4; ++i) {
    cv::Mat P(3, 4, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        P.at<double>(r, c) = calibration.P[i](r, c);
    out << "P" + std::to_string(i) << P;
  }
  out << "image_width" << calibration.image_size.width;
  out << "image_height" << calibration.image_size.height;
  if (calibration.has_velodyne) {
    cv::Mat T(4, 4, CV_64F);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        T.at<double>(r, c) = calibration.T_cam0_velo.matrix()(r, c);
    out << "T_cam0_velo" << T;
    const Calibration::Lidar& lidar = calibration.lidar;
    out << "lidar_sweeping" << (lidar.sweeping ? 1 : 0);
    if (lidar.rings > 0)
      out << "lidar_rings" << lidar.rings;
    if (!lidar.beam_elevations_deg.empty())
      out << "lidar_beam_elevations_deg"
          << cv::Mat(1, static_cast<int>(lidar.beam_elevations_deg.size()), CV_64F,
                     const_cast<double*>(lidar.beam_elevations_deg.data()));
  }
  const std::string text = out.releaseAndGetString();
  writeStreamAtomically(path, [&](std::ostream& stream) { stream << text; });
}

void saveOdometryCalibration(const Calibration& calibration, const std::string& path) {
  writeStreamAtomically(path, [&](std::ostream& out) {
    out << std::scientific << std::setprecision(12);
    auto row = [&](const std::string& key, const Eigen::Matrix<double, 3, 4>& M) {
      out << key << ":";
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c)
          out << ' ' << M(r, c);
      out << '\n';
    };
    for (int i = 0; i < 4; ++i)
      row("P" + std::to_string(i), calibration.P[i]);
    if (calibration.has_velodyne)
      row("Tr", calibration.T_cam0_velo.matrix().topRows<3>());
  });
}

} // namespace msf
