// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/io/poses.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace fs = std::filesystem;

namespace msf {

PoseList loadOdometryPoses(const std::string& path) {
  requireFile(path, "poses");
  std::ifstream in(path);
  PoseList poses;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') // a blank line or a comment, as TUM files have
      continue;
    std::istringstream ss(line);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const std::string where = "poses '" + path + "' line " + std::to_string(line_no);
    int n = 0;
    std::string token;
    while (ss >> token) {
      // Token by token: ">> double" stops at "nan" or "1.0x" and the count was then wrong.
      double v = 0.0;
      std::size_t used = 0;
      try {
        v = std::stod(token, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != token.size())
        throw IOError(where + ": value " + std::to_string(n + 1) + " '" + token + "' is not a number");
      if (!std::isfinite(v))
        throw IOError(where + ": value " + std::to_string(n + 1) + " '" + token + "' is not finite");
      if (n < 12)
        T.matrix()(n / 4, n % 4) = v;
      ++n;
    }
    if (n != 12)
      throw IOError(where + ": expected 12 numbers (a 3x4 row-major matrix), got " + std::to_string(n));
    try {
      limits::checkRigid(T, where);
    } catch (const InvalidInputError& e) {
      throw IOError(e.what());
    }
    poses.push_back(T);
  }
  return poses;
}

void saveOdometryPoses(const std::string& path, const PoseList& T_world_cam0) {
  writeStreamAtomically(path, [&](std::ostream& out) {
    out << std::scientific << std::setprecision(9);
    for (const auto& T : T_world_cam0) {
      for (int n = 0; n < 12; ++n)
        out << (n ? " " : "") << T.matrix()(n / 4, n % 4);
      out << '\n';
    }
  });
}

std::vector<OxtsRecord> loadOxts(const std::string& oxts_data_dir) {
  requireDirectory(oxts_data_dir, "oxts folder");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(oxts_data_dir))
    if (e.is_regular_file() && e.path().extension() == ".txt")
      files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<OxtsRecord> records;
  for (const auto& f : files)
    records.push_back(loadOxtsRecord(f.string()));
  return records;
}

OxtsRecord loadOxtsRecord(const std::string& path) {
  std::ifstream in(path);
  OxtsRecord r;
  if (!(in >> r.lat >> r.lon >> r.alt >> r.roll >> r.pitch >> r.yaw))
    throw IOError("oxts '" + path + "': expected at least 6 numbers (lat lon alt roll pitch yaw)");
  for (const double v : {r.lat, r.lon, r.alt, r.roll, r.pitch, r.yaw})
    if (!std::isfinite(v))
      throw IOError("oxts '" + path + "': a value of lat lon alt roll pitch yaw is not finite");
  return r;
}

PoseList oxtsToCameraPoses(const std::vector<OxtsRecord>& oxts, const Calibration& calibration) {
  PoseList poses;
  if (oxts.empty())
    return poses;
  if (!calibration.has_imu)
    throw CalibrationError("calibration '" + calibration.source +
                           "' has no calib_imu_to_velo.txt, needed to turn OXTS into camera poses");
  constexpr double kEarthRadius = 6378137.0; // metres, as the devkit
  const double scale = std::cos(oxts.front().lat * M_PI / 180.0);
  auto imuPose = [&](const OxtsRecord& r) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << scale * r.lon * M_PI * kEarthRadius / 180.0,
        scale * kEarthRadius * std::log(std::tan((90.0 + r.lat) * M_PI / 360.0)), r.alt;
    T.linear() = (Eigen::AngleAxisd(r.yaw, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(r.pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(r.roll, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    return T;
  };
  const Eigen::Isometry3d T_imu_cam0 = (calibration.T_cam0_velo * calibration.T_velo_imu).inverse();
  const Eigen::Isometry3d T_cam0first_w = (imuPose(oxts.front()) * T_imu_cam0).inverse();
  poses.reserve(oxts.size());
  for (const auto& r : oxts)
    poses.push_back(T_cam0first_w * imuPose(r) * T_imu_cam0);
  return poses;
}

} // namespace msf
