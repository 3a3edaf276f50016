// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/yaml_file.h>
#include <msf/io/rig_file.h>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <sstream>

namespace msf {

namespace {

/// A rig file's nodes with the file's name for every message.
class RigReader {
public:
  /// The file read as configuration files are (loadYamlFile): its size and nesting bounded, a key
  /// written twice refused (a lookup would see the first only).
  explicit RigReader(const std::string& path) : path_(path), root_(loadYamlFile(path, "rig file")) {
    if (!root_.IsMap())
      throw CalibrationError("rig file '" + path + "' is not a map of keys (image_width, left, lidar, ...)");
    refuseRepeatedKeys(root_, "");
    refuseUnknownKeys(root_, "a rig file",
                      {"image_width", "image_height", "left", "right", "baseline_m", "color", "color_right", "lidar"});
  }

  const YAML::Node& root() const { return root_; }

  /// Throws naming the first key of `map` (the file's `name`: "a rig file", "lidar") that is not
  /// in `known`: a misspelt key would leave its value at the default, a 16-beam LiDAR read as
  /// KITTI's.
  void refuseUnknownKeys(const YAML::Node& map, const std::string& name,
                         std::initializer_list<const char*> known) const {
    for (const auto& entry : map) {
      const std::string key = entry.first.Scalar();
      if (std::any_of(known.begin(), known.end(), [&](const char* k) { return key == k; }))
        continue;
      std::string keys;
      for (const char* k : known)
        keys += (keys.empty() ? "" : ", ") + std::string(k);
      throw CalibrationError(yamlWhere("rig file", path_, entry.first) + "'" + key + "' is not a key of " + name +
                             " (" + keys + ")");
    }
  }

  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw CalibrationError("rig file '" + path_ + "': " + key + " " + why);
  }

  double number(const YAML::Node& node, const std::string& key) const {
    if (!node || !node.IsScalar())
      fail(key, node ? "must be a number" : "is missing");
    double value = 0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(key, "must be a number, not '" + node.Scalar() + "'");
    }
    if (!std::isfinite(value))
      fail(key, "must be finite, not " + node.Scalar());
    return value;
  }

  int whole(const YAML::Node& node, const std::string& key, int lo, int hi) const {
    const double value = number(node, key);
    if (value != std::floor(value) || value < lo || value > hi)
      fail(key, "must be a whole number in " + std::to_string(lo) + ".." + std::to_string(hi) + ", not " +
                    node.Scalar());
    return static_cast<int>(value);
  }

  std::vector<double> numbers(const YAML::Node& node, const std::string& key, std::size_t count) const {
    if (!node || !node.IsSequence())
      fail(key, node ? "must be a list of numbers" : "is missing");
    if (count > 0 && node.size() != count)
      fail(key, "must hold " + std::to_string(count) + " numbers, not " + std::to_string(node.size()));
    std::vector<double> values;
    for (std::size_t i = 0; i < node.size(); ++i)
      values.push_back(number(node[i], key + "[" + std::to_string(i) + "]"));
    return values;
  }

  /// A camera's P: its `P` (12 numbers, row-major) or its fx, fy, cx, cy (and Tx = 0).
  Calibration::Projection projection(const YAML::Node& camera, const std::string& key) const {
    if (!camera || !camera.IsMap())
      fail(key, camera ? "must be a map (fx, fy, cx, cy, or P)" : "is missing");
    refuseUnknownKeys(camera, key, {"fx", "fy", "cx", "cy", "P"});
    Calibration::Projection P = Calibration::Projection::Zero();
    if (camera["P"]) {
      const std::vector<double> p = numbers(camera["P"], key + ".P", 12);
      for (int k = 0; k < 12; ++k)
        P(k / 4, k % 4) = p[static_cast<std::size_t>(k)];
    } else {
      P(0, 0) = number(camera["fx"], key + ".fx");
      P(1, 1) = number(camera["fy"], key + ".fy");
      P(0, 2) = number(camera["cx"], key + ".cx");
      P(1, 2) = number(camera["cy"], key + ".cy");
      P(2, 2) = 1.0;
    }
    if (!(P(0, 0) > 0.0) || !(P(1, 1) > 0.0))
      fail(key, "needs focal lengths > 0 (fx " + std::to_string(P(0, 0)) + ", fy " + std::to_string(P(1, 1)) + ")");
    return P;
  }

private:
  void refuseRepeatedKeys(const YAML::Node& map, const std::string& prefix) const {
    if (const auto repeated = findRepeatedKey(map))
      throw CalibrationError(yamlWhere("rig file", path_, map) + prefix + repeated->key + " appears twice (lines " +
                             std::to_string(repeated->first_line) + " and " +
                             std::to_string(repeated->second_line) + ")");
    for (const auto& entry : map)
      if (entry.second.IsMap())
        refuseRepeatedKeys(entry.second, prefix + entry.first.Scalar() + ".");
  }

  std::string path_;
  YAML::Node root_;
};

/// Camera 1 `baseline_m` to the right of camera 0: Tx = -fx B, as KITTI's and ROS's P.
Calibration::Projection rightOf(const Calibration::Projection& left, double baseline_m) {
  Calibration::Projection P = left;
  P(0, 3) = -left(0, 0) * baseline_m;
  return P;
}

void readLidar(const RigReader& rig, Calibration& calibration) {
  const YAML::Node lidar = rig.root()["lidar"];
  if (!lidar) {
    calibration.has_velodyne = false;
    return;
  }
  if (!lidar.IsMap())
    rig.fail("lidar", "must be a map (T_cam_lidar, rings, beam_elevations_deg, sweeping)");
  rig.refuseUnknownKeys(lidar, "lidar", {"T_cam_lidar", "rings", "beam_elevations_deg", "sweeping"});
  const std::vector<double> T = rig.numbers(lidar["T_cam_lidar"], "lidar.T_cam_lidar", 16);
  Eigen::Matrix4d M;
  for (int k = 0; k < 16; ++k)
    M(k / 4, k % 4) = T[static_cast<std::size_t>(k)];
  if (!M.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)))
    rig.fail("lidar.T_cam_lidar", "must end in the row 0 0 0 1");
  if (!(M.topLeftCorner<3, 3>().transpose() * M.topLeftCorner<3, 3>()).isApprox(Eigen::Matrix3d::Identity(), 1e-3) ||
      M.topLeftCorner<3, 3>().determinant() < 0)
    rig.fail("lidar.T_cam_lidar", "must be a rigid transform (its 3x3 part a rotation)");
  calibration.T_cam0_velo.matrix() = M;
  calibration.has_velodyne = true;
  if (lidar["rings"])
    calibration.lidar.rings = rig.whole(lidar["rings"], "lidar.rings", 1, 1024);
  if (lidar["beam_elevations_deg"]) {
    calibration.lidar.beam_elevations_deg = rig.numbers(lidar["beam_elevations_deg"], "lidar.beam_elevations_deg", 0);
    const auto& e = calibration.lidar.beam_elevations_deg;
    if (calibration.lidar.rings > 0 && e.size() != static_cast<std::size_t>(calibration.lidar.rings))
      rig.fail("lidar.beam_elevations_deg", "must hold one elevation per ring (" +
                                                std::to_string(calibration.lidar.rings) + "), not " +
                                                std::to_string(e.size()));
    for (std::size_t i = 1; i < e.size(); ++i)
      if (!(e[i] > e[i - 1]))
        rig.fail("lidar.beam_elevations_deg", "must rise from the lowest beam to the highest");
    calibration.lidar.rings = static_cast<int>(e.size());
  }
  if (lidar["sweeping"]) {
    try {
      calibration.lidar.sweeping = lidar["sweeping"].as<bool>();
    } catch (const YAML::Exception&) {
      rig.fail("lidar.sweeping", "must be true or false");
    }
  }
}

// The shortest text that reads back as the same double: 707.0912, not 707.09119999999996.
std::string shortest(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

void emitMatrix(YAML::Emitter& out, const double* values, int count) {
  out << YAML::Flow << YAML::BeginSeq;
  for (int k = 0; k < count; ++k)
    out << shortest(values[k]);
  out << YAML::EndSeq;
}

std::vector<double> rowMajor(const Calibration::Projection& P) {
  std::vector<double> v;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      v.push_back(P(r, c));
  return v;
}

} // namespace

bool isRigFile(const std::string& path) {
  try {
    const YAML::Node root = loadYamlFile(path, "rig file");
    if (!root.IsMap() || root["P0"]) // the OpenCV camera file (saveCalibrationYaml) has P0..P3
      return false;
    for (const char* key : {"image_width", "image_height", "left", "right", "baseline_m", "lidar"})
      if (root[key])
        return true;
    // OpenCV reads no YAML without its "%YAML" line: a map without one is a rig file whose keys are
    // all misspelt, and its reader names them.
    std::ifstream file(path);
    std::string first_line;
    std::getline(file, first_line);
    return first_line.rfind("%YAML", 0) != 0;
  } catch (const Error&) {
    return false;
  }
}

Calibration loadRigFile(const std::string& path) {
  const RigReader rig(path);
  Calibration calibration;
  calibration.source = path;
  const YAML::Node& root = rig.root();
  calibration.image_size.width = rig.whole(root["image_width"], "image_width", 1, 1 << 16);
  calibration.image_size.height = rig.whole(root["image_height"], "image_height", 1, 1 << 16);
  const Calibration::Projection left = rig.projection(root["left"], "left");
  if (left(0, 3) != 0.0 || left(1, 3) != 0.0)
    rig.fail("left.P", "must have no translation column: the left camera is the reference (camera 0)");
  calibration.P[0] = left;
  if (root["right"] && root["baseline_m"])
    rig.fail("baseline_m", "and right are both given: give one of them");
  if (root["right"]) {
    calibration.P[1] = rig.projection(root["right"], "right");
  } else {
    const double baseline = rig.number(root["baseline_m"], "baseline_m (or right)");
    calibration.P[1] = rightOf(left, baseline);
  }
  if (!(calibration.P[1](0, 3) < 0.0))
    rig.fail(root["right"] ? "right.P" : "baseline_m",
             "must put the right camera to the right of the left one (Tx = -fx * baseline < 0, baseline > 0): "
             "are the cameras swapped?");
  calibration.P[2] = root["color"] ? rig.projection(root["color"], "color") : left;
  if (root["color_right"]) {
    calibration.P[3] = rig.projection(root["color_right"], "color_right");
  } else { // the colour pair's right camera, unused by the stages: the grey pair's baseline
    calibration.P[3] = calibration.P[2];
    calibration.P[3](0, 3) -= calibration.P[2](0, 0) * calibration.baseline(0, 1);
  }
  readLidar(rig, calibration);
  calibration.validate();
  return calibration;
}

Calibration makeRig(cv::Size image_size, double fx, double fy, double cx, double cy, double baseline_m,
                    const Eigen::Isometry3d* T_cam_lidar, const Calibration::Lidar& lidar) {
  Calibration c;
  c.source = "a rig made in code";
  if (!(baseline_m > 0.0))
    throw CalibrationError(c.source + ": the baseline must be > 0 (the right camera to the right of the left one), "
                                      "not " + std::to_string(baseline_m) + " m");
  c.image_size = image_size;
  Calibration::Projection left = Calibration::Projection::Zero();
  left(0, 0) = fx;
  left(1, 1) = fy;
  left(0, 2) = cx;
  left(1, 2) = cy;
  left(2, 2) = 1.0;
  c.P = {left, rightOf(left, baseline_m), left, rightOf(left, baseline_m)};
  c.has_velodyne = T_cam_lidar != nullptr;
  if (T_cam_lidar)
    c.T_cam0_velo = *T_cam_lidar;
  c.lidar = lidar;
  if (!lidar.beam_elevations_deg.empty()) // validate() checks that they rise
    c.lidar.rings = static_cast<int>(lidar.beam_elevations_deg.size());
  if (image_size.area() <= 0)
    throw CalibrationError(c.source + ": the image size must be given, not " + std::to_string(image_size.width) +
                           "x" + std::to_string(image_size.height));
  c.validate();
  return c;
}

void saveRigFile(const Calibration& c, const std::string& path) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "image_width" << YAML::Value << c.image_size.width;
  out << YAML::Key << "image_height" << YAML::Value << c.image_size.height;
  for (const auto& [key, camera] :
       {std::pair<const char*, int>{"left", 0}, {"right", 1}, {"color", 2}, {"color_right", 3}}) {
    out << YAML::Key << key << YAML::Value << YAML::BeginMap << YAML::Key << "P" << YAML::Value;
    const std::vector<double> P = rowMajor(c.P[camera]);
    emitMatrix(out, P.data(), 12);
    out << YAML::EndMap;
  }
  if (c.has_velodyne) {
    out << YAML::Key << "lidar" << YAML::Value << YAML::BeginMap << YAML::Key << "T_cam_lidar" << YAML::Value;
    Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T = c.T_cam0_velo.matrix();
    emitMatrix(out, T.data(), 16);
    if (c.lidar.rings > 0)
      out << YAML::Key << "rings" << YAML::Value << c.lidar.rings;
    if (!c.lidar.beam_elevations_deg.empty()) {
      out << YAML::Key << "beam_elevations_deg" << YAML::Value;
      emitMatrix(out, c.lidar.beam_elevations_deg.data(), static_cast<int>(c.lidar.beam_elevations_deg.size()));
    }
    out << YAML::Key << "sweeping" << YAML::Value << c.lidar.sweeping << YAML::EndMap;
  }
  out << YAML::EndMap;
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream file(tmp);
    file << "# msfusion rig file: rectified cameras (left = camera 0), the LiDAR's extrinsic\n" << out.c_str() << "\n";
    file.close();
    if (!file)
      throw IOError("cannot write rig file '" + path + "'");
  });
}

} // namespace msf
