// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/io/tum_poses.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace msf {

namespace {

/// The numbers of a line, or throws IOError naming `where` and the token that is not one.
std::vector<double> numbersOf(const std::string& line, const std::string& where) {
  std::istringstream ss(line);
  std::vector<double> values;
  std::string token;
  while (ss >> token) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size() || !std::isfinite(v))
      throw IOError(where + ": value " + std::to_string(values.size() + 1) + " '" + token + "' is not a finite number");
    values.push_back(v);
  }
  return values;
}

bool isContent(const std::string& line) {
  const std::size_t first = line.find_first_not_of(" \t\r");
  return first != std::string::npos && line[first] != '#';
}

} // namespace

StampedPoses loadTumPoses(const std::string& path) {
  requireFile(path, "poses");
  std::ifstream in(path);
  StampedPoses out;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (!isContent(line))
      continue;
    const std::string where = "poses '" + path + "' line " + std::to_string(line_no);
    const std::vector<double> v = numbersOf(line, where);
    if (v.size() != 8)
      throw IOError(where + ": expected 8 numbers (timestamp tx ty tz qx qy qz qw), got " + std::to_string(v.size()));
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw IOError(where + ": the quaternion (qx qy qz qw) has norm " + std::to_string(q.norm()) + ", not 1");
    if (!out.timestamps.empty() && !(v[0] > out.timestamps.back()))
      throw IOError(where + ": time " + std::to_string(v[0]) + " does not follow the line before's");
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() << v[1], v[2], v[3];
    try {
      limits::checkRigid(T, where);
    } catch (const InvalidInputError& e) {
      throw IOError(e.what());
    }
    out.timestamps.push_back(v[0]);
    out.poses.push_back(T);
  }
  return out;
}

void saveTumPoses(const std::string& path, const StampedPoses& poses) {
  if (poses.timestamps.size() != poses.poses.size())
    throw InvalidInputError("saveTumPoses: " + std::to_string(poses.timestamps.size()) + " times for " +
                            std::to_string(poses.poses.size()) + " poses");
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << "# timestamp tx ty tz qx qy qz qw (T_world_cam0)\n" << std::setprecision(17);
    for (std::size_t i = 0; i < poses.poses.size(); ++i) {
      const Eigen::Quaterniond q(poses.poses[i].rotation());
      const Eigen::Vector3d t = poses.poses[i].translation();
      out << poses.timestamps[i] << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y()
          << ' ' << q.z() << ' ' << q.w() << '\n';
    }
    out.close();
    if (!out)
      throw IOError("cannot write poses '" + path + "'");
  });
}

bool isTumPoses(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (isContent(line)) {
      std::istringstream ss(line);
      std::string token;
      int n = 0;
      while (ss >> token)
        ++n;
      return n == 8;
    }
  return false;
}

} // namespace msf
